//! One vocabulary of render settings. The scene file's `[render]` table, `twinpath bench
//! --variant NAME:key=value,...` and the command-line flags all go through
//! [`RenderSettings::set`], so a setting has one name, one parser, one check and one default;
//! the settings become the kernel's `u32` codes only where `Scene::params` fills `RenderParams`.

use kernel::scene::{light_sampling, light_selection, mis, roulette, sampler};

/// An enum whose values have one name each in the vocabulary, and a kernel code.
macro_rules! choice {
    ($(#[$meta:meta])* $name:ident { $($(#[$vmeta:meta])* $variant:ident = $text:literal => $code:expr),+ $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum $name {
            $($(#[$vmeta])* $variant),+
        }
        impl $name {
            /// The names the vocabulary accepts, in the order of the variants.
            pub const NAMES: &'static [&'static str] = &[$($text),+];
            /// The value named `text`.
            pub fn parse(text: &str) -> Option<Self> {
                match text {
                    $($text => Some(Self::$variant),)+
                    _ => None,
                }
            }
            /// Its name in the vocabulary.
            pub fn name(self) -> &'static str {
                match self {
                    $(Self::$variant => $text),+
                }
            }
            /// The kernel's code for it (`kernel::scene`).
            pub fn code(self) -> u32 {
                match self {
                    $(Self::$variant => $code),+
                }
            }
        }
    };
}

choice! {
    /// How Russian roulette chooses a path's survival probability q.
    Roulette {
        /// A constant q (`russian_roulette`, the seed's 0.8).
        Constant = "constant" => roulette::CONSTANT,
        /// q = min(1, the largest throughput component), as in pbrt-v4 and Mitsuba 3.
        Throughput = "throughput" => roulette::THROUGHPUT,
    }
}

choice! {
    /// How light sampling and BRDF sampling are weighted.
    Mis {
        /// Veach's power heuristic (beta = 2).
        Power = "power" => mis::POWER,
        /// The seed's fixed 1/2 weights.
        Half = "half" => mis::HALF,
        /// Light sampling alone (BSDF-sampled hits of lights add nothing unless a delta lobe
        /// chose the direction): for comparing strategies, not for renders.
        Light = "light" => mis::LIGHT_ONLY,
        /// BSDF sampling alone (no light samples): for comparing strategies.
        Bsdf = "bsdf" => mis::BSDF_ONLY,
    }
}

choice! {
    /// How next-event estimation picks a point on a light.
    LightSampling {
        /// By the solid angle the light subtends: a direction uniform in a sphere's cone, or
        /// in a triangle's spherical triangle where its solid angle allows.
        SolidAngle = "solid_angle" => light_sampling::SOLID_ANGLE,
        /// A uniform point on the light's surface (the seed's way for spheres).
        Area = "area" => light_sampling::AREA,
    }
}

choice! {
    /// How next-event estimation picks one of several lights.
    LightSelection {
        /// Proportionally to each light's power (alias table).
        Power = "power" => light_selection::POWER,
        /// The seed's uniform choice.
        Uniform = "uniform" => light_selection::UNIFORM,
    }
}

choice! {
    /// Where each sample's random numbers come from.
    Sampler {
        /// Independent uniform numbers per dimension.
        Independent = "independent" => sampler::INDEPENDENT,
        /// Owen-scrambled Sobol points, stratified within each pixel.
        Sobol = "sobol" => sampler::SOBOL,
    }
}

/// Whether and how often paths split at their first vertex (`kernel::split`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// One continuation: every path as it always was.
    Off,
    /// Continuations per 16 x 16 tile, learned by a pilot render (`crate::split_pilot`).
    Auto,
    /// This many continuations (1 to `kernel::split::MAX_CONTINUATIONS`) everywhere.
    Fixed(u32),
}

impl Split {
    /// The value written `text`: "off", "auto" or a count.
    pub fn parse(text: &str) -> Result<Self, String> {
        match text {
            "off" => Ok(Split::Off),
            "auto" => Ok(Split::Auto),
            _ => match integer(text, 1, kernel::split::MAX_CONTINUATIONS as u64) {
                Ok(n) => Ok(Split::Fixed(n)),
                Err(e) => Err(format!("{e} (split: off, auto or a count)")),
            },
        }
    }

    /// Its name in the vocabulary.
    pub fn name(self) -> String {
        match self {
            Split::Off => "off".to_string(),
            Split::Auto => "auto".to_string(),
            Split::Fixed(n) => n.to_string(),
        }
    }
}

/// Integrator settings of a render. `Default` holds every default (the best measured choices,
/// `docs/performance.md`); [`RenderSettings::set`] is the only way the outside changes one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub spp: u32,
    pub seed: u32,
    pub roulette: Roulette,
    /// Survival probability of the constant roulette.
    pub rr_probability: f32,
    /// First path vertex (1 = the camera ray's hit) whose extension roulette decides; `None`:
    /// the roulette's own default ([`RenderSettings::roulette_start_depth`]).
    pub rr_start_depth: Option<u32>,
    pub mis: Mis,
    /// A guard on the path length (`u32::MAX`: none, unbiased).
    pub max_depth: u32,
    pub light_sampling: LightSampling,
    pub light_selection: LightSelection,
    pub sampler: Sampler,
    /// Compile the kernel for what the scene needs (`kernel::features`); false: generic path.
    pub specialize: bool,
    /// CPU: trace sixteen paths at a time, SIMD over rays (`cpu::packet_paths`: against every
    /// primitive of a scene of at most `cpu::packet::MAX_PRIMITIVES` without instances or
    /// holes, else through the BVH); false: one path at a time.
    pub packets: bool,
    /// Adaptive sampling's target relative error of a pixel (0: off; `kernel::adaptive`).
    pub adaptive_target: f32,
    /// Splitting at the first vertex (`kernel::split`).
    pub split: Split,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 64,
            seed: 0,
            roulette: Roulette::Throughput,
            rr_probability: 0.8,
            rr_start_depth: None,
            mis: Mis::Power,
            max_depth: u32::MAX,
            light_sampling: LightSampling::SolidAngle,
            light_selection: LightSelection::Power,
            sampler: Sampler::Sobol,
            specialize: true,
            packets: true,
            adaptive_target: 0.0,
            split: Split::Off,
        }
    }
}

/// Every key [`RenderSettings::set`] accepts, with the values it takes.
pub const SETTINGS: &[(&str, &str)] = &[
    ("spp", "samples per pixel, an integer >= 1"),
    ("seed", "an integer in 0..=4294967295"),
    ("roulette", "constant | throughput"),
    (
        "russian_roulette",
        "the constant roulette's survival probability, in (0, 1]",
    ),
    (
        "rr_start_depth",
        "first vertex roulette may end (1 = camera hit); default 1 (constant), 5 (throughput)",
    ),
    ("mis", "power | half | light | bsdf"),
    ("max_depth", "guard on the path length, an integer >= 1"),
    ("light_sampling", "solid_angle | area"),
    ("light_selection", "power | uniform"),
    ("sampler", "sobol | independent"),
    ("specialize", "on | off"),
    ("packets", "on | off"),
    (
        "adaptive_target",
        "adaptive sampling's relative error per pixel, >= 0 (0: off)",
    ),
    (
        "split",
        "continuations at the first vertex: off | auto (learned per tile) | 1..=4",
    ),
];

/// Other names accepted for a key (the bench variants' short forms).
const ALIASES: &[(&str, &str)] = &[("rr", "russian_roulette"), ("adaptive", "adaptive_target")];

impl RenderSettings {
    /// Whether the render samples adaptively (a target error is set): the one place the host
    /// decides it; the kernel reads it from the launch parameters (`kernel::adaptive`).
    pub fn adaptive(&self) -> bool {
        self.adaptive_target > 0.0
    }

    /// Sets `key` (a name of [`SETTINGS`] or an alias) to the value written `value`. The error
    /// says what is wrong with the value, or lists the keys; callers add where it came from.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), String> {
        let key = ALIASES
            .iter()
            .find(|(alias, _)| *alias == key)
            .map_or(key, |(_, k)| k);
        match key {
            "spp" => self.spp = integer(value, 1, u32::MAX as u64)?,
            "seed" => self.seed = integer(value, 0, u32::MAX as u64)?,
            "roulette" => self.roulette = choice(value, Roulette::parse, Roulette::NAMES)?,
            "russian_roulette" => {
                let q = float(value)?;
                if !(q > 0.0 && q <= 1.0) {
                    return Err(format!("{q} is not a probability in (0, 1]"));
                }
                self.rr_probability = q;
            }
            "rr_start_depth" => self.rr_start_depth = Some(integer(value, 0, u32::MAX as u64)?),
            "mis" => self.mis = choice(value, Mis::parse, Mis::NAMES)?,
            "max_depth" => self.max_depth = integer(value, 1, u32::MAX as u64)?,
            "light_sampling" => {
                self.light_sampling = choice(value, LightSampling::parse, LightSampling::NAMES)?
            }
            "light_selection" => {
                self.light_selection = choice(value, LightSelection::parse, LightSelection::NAMES)?
            }
            "sampler" => self.sampler = choice(value, Sampler::parse, Sampler::NAMES)?,
            "specialize" => self.specialize = switch(value)?,
            "packets" => self.packets = switch(value)?,
            "adaptive_target" => {
                let t = float(value)?;
                if !(t >= 0.0 && t.is_finite()) {
                    return Err(format!("{t} is not a finite relative error >= 0"));
                }
                self.adaptive_target = t;
            }
            "split" => self.split = Split::parse(value)?,
            _ => {
                let keys: Vec<&str> = SETTINGS.iter().map(|(k, _)| *k).collect();
                return Err(format!(
                    "unknown setting '{key}' (settings: {})",
                    keys.join(", ")
                ));
            }
        }
        Ok(())
    }

    /// Every setting of [`SETTINGS`] with its value as the vocabulary writes it (what
    /// [`RenderSettings::set`] reads back), in [`SETTINGS`]'s order.
    pub fn entries(&self) -> Vec<(&'static str, String)> {
        let on_off = |b: bool| if b { "on" } else { "off" }.to_string();
        let value = |key: &str| match key {
            "spp" => self.spp.to_string(),
            "seed" => self.seed.to_string(),
            "roulette" => self.roulette.name().to_string(),
            "russian_roulette" => self.rr_probability.to_string(),
            "rr_start_depth" => self.roulette_start_depth().to_string(),
            "mis" => self.mis.name().to_string(),
            "max_depth" => self.max_depth.to_string(),
            "light_sampling" => self.light_sampling.name().to_string(),
            "light_selection" => self.light_selection.name().to_string(),
            "sampler" => self.sampler.name().to_string(),
            "specialize" => on_off(self.specialize),
            "packets" => on_off(self.packets),
            "adaptive_target" => self.adaptive_target.to_string(),
            "split" => self.split.name(),
            _ => unreachable!("every key of SETTINGS has a value"),
        };
        SETTINGS.iter().map(|&(k, _)| (k, value(k))).collect()
    }

    /// The first vertex whose extension roulette decides: the setting, else 1 for constant
    /// roulette (the seed's) and 5 for throughput roulette (its q is 1 on the first bounces of
    /// bright paths anyway; starting later measured best on Cornell, `docs/performance.md`).
    pub fn roulette_start_depth(&self) -> u32 {
        self.rr_start_depth.unwrap_or(match self.roulette {
            Roulette::Constant => 1,
            Roulette::Throughput => 5,
        })
    }
}

fn integer(value: &str, min: u64, max: u64) -> Result<u32, String> {
    match value.parse::<i64>() {
        Ok(x) if x >= min as i64 && x <= max as i64 => Ok(x as u32),
        Ok(x) => Err(format!("{x} is outside {min}..={max}")),
        Err(_) => Err(format!("'{value}' is not an integer")),
    }
}

fn float(value: &str) -> Result<f32, String> {
    value
        .parse::<f32>()
        .map_err(|_| format!("'{value}' is not a number"))
}

fn switch(value: &str) -> Result<bool, String> {
    match value {
        "on" | "true" => Ok(true),
        "off" | "false" => Ok(false),
        _ => Err(format!("'{value}' is not \"on\" or \"off\"")),
    }
}

fn choice<T>(value: &str, parse: fn(&str) -> Option<T>, names: &[&str]) -> Result<T, String> {
    parse(value).ok_or_else(|| {
        let quoted: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
        let (last, rest) = quoted.split_last().expect("a choice has names");
        if rest.is_empty() {
            format!("'{value}' is not {last}")
        } else {
            format!("'{value}' is not {} or {last}", rest.join(", "))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `entries` writes what `set` reads: every setting survives the round trip (part files
    /// compare settings by these texts).
    #[test]
    fn entries_read_back_as_the_same_settings() {
        let mut changed = RenderSettings::default();
        for (k, v) in [
            ("spp", "5"),
            ("seed", "7"),
            ("roulette", "constant"),
            ("russian_roulette", "0.3"),
            ("rr_start_depth", "2"),
            ("mis", "half"),
            ("max_depth", "9"),
            ("light_sampling", "area"),
            ("light_selection", "uniform"),
            ("sampler", "independent"),
            ("specialize", "off"),
            ("packets", "off"),
            ("adaptive_target", "0.05"),
            ("split", "3"),
        ] {
            changed.set(k, v).unwrap();
        }
        for settings in [RenderSettings::default(), changed] {
            let entries = settings.entries();
            assert_eq!(entries.len(), SETTINGS.len());
            let mut back = RenderSettings {
                spp: 1,
                ..Default::default()
            };
            for (k, v) in &entries {
                back.set(k, v).unwrap();
            }
            // The roulette's default start depth is written out, so compare effective values.
            assert_eq!(back.roulette_start_depth(), settings.roulette_start_depth());
            back.rr_start_depth = settings.rr_start_depth;
            assert_eq!(back, settings);
        }
    }
}
