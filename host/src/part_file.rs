//! Part files: one part of a render (a range of sample indices), written by `twinpath render
//! --part I/N` or `--samples A..B` and combined by `twinpath merge` (`crate::merge`).
//!
//! A part file is an OpenEXR image whose pixels hold the film's exact fixed-point sums
//! (`crate::fixed_sum`) as 32-bit words, and whose header says what was rendered: the format
//! version, twinpath's version, the scene's input files and their hashes, every effective
//! setting, the seed, sampler, backend and sample range. Channels per pixel:
//! `R`, `G`, `B` (the part's mean, f32: any EXR viewer shows a preview), `count` (u32),
//! `<C>.sum.<k>` (the i128 sum of channel C, word k, least significant first, k in 0..4) and
//! `<C>.sumsq.<k>` (the f64 sum of squares' bits, k in 0..2). docs/parts.md has the layout.

use crate::film::Film;
use crate::fixed_sum::FixedSum;
use crate::sample_range::{Part, SampleRange};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use anyhow::{anyhow, bail, Context, Result};
use exr::prelude::*;
use std::collections::HashMap;
use std::path::Path;

/// The part-file format this build writes and reads.
pub const FORMAT_VERSION: u32 = 1;

/// What a part file says about its render.
#[derive(Clone, Debug, PartialEq)]
pub struct PartHeader {
    /// twinpath's version that rendered it.
    pub version: String,
    /// The scene's name (its file, as given on the command line).
    pub scene: String,
    /// The files the scene read, with the hex BLAKE3 hash of each (`scene::inputs`).
    pub inputs: Vec<(String, String)>,
    /// Every effective setting that decides a sample's value, as `(name, value)`: the render
    /// settings but `spp` (the sample range replaces it), and the camera.
    pub settings: Vec<(String, String)>,
    pub seed: u32,
    pub sampler: String,
    /// `cpu` or `gpu`.
    pub backend: String,
    /// The sample indices the part holds.
    pub samples: SampleRange,
    /// With `--part I/N`: which part, of which whole range.
    pub part: Option<(Part, SampleRange)>,
}

impl PartHeader {
    /// The header of a part of `scene`'s render with `render` holding `samples`.
    pub fn new(
        scene: &Scene,
        render: &RenderSettings,
        backend: &str,
        samples: SampleRange,
    ) -> Self {
        let mut settings: Vec<(String, String)> = render
            .entries()
            .into_iter()
            .filter(|(k, _)| *k != "spp")
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        settings.push(("camera".into(), format!("{:?}", scene.camera)));
        Self {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: scene.name.clone(),
            inputs: scene
                .inputs
                .iter()
                .map(|f| (f.path.display().to_string(), f.hash.to_hex().to_string()))
                .collect(),
            settings,
            seed: render.seed,
            sampler: render.sampler.name().to_string(),
            backend: backend.to_string(),
            samples,
            part: None,
        }
    }

    /// A hash of every input file's content (not its name).
    pub fn scene_hash(&self) -> String {
        let mut h = blake3::Hasher::new();
        for (_, hash) in &self.inputs {
            h.update(hash.as_bytes());
        }
        h.finalize().to_hex().to_string()
    }

    /// A hash of every setting in [`PartHeader::settings`].
    pub fn settings_hash(&self) -> String {
        let mut h = blake3::Hasher::new();
        for (k, v) in &self.settings {
            h.update(format!("{k}={v}\n").as_bytes());
        }
        h.finalize().to_hex().to_string()
    }

    /// The header as EXR attributes named `twinpath.*` (values UTF-8).
    fn attributes(&self) -> Vec<(&'static str, String)> {
        let lines = |pairs: &mut dyn Iterator<Item = (&String, &String)>, sep: &str| {
            pairs
                .map(|(a, b)| format!("{a}{sep}{b}"))
                .collect::<Vec<_>>()
                .join("\n")
        };
        let mut a = vec![
            ("twinpath.format", FORMAT_VERSION.to_string()),
            ("twinpath.version", self.version.clone()),
            ("twinpath.scene", self.scene.clone()),
            ("twinpath.scene_hash", self.scene_hash()),
            // "HASH PATH" lines: a path may hold spaces, a hex hash never does.
            (
                "twinpath.inputs",
                lines(
                    &mut self.inputs.iter().map(|(path, hash)| (hash, path)),
                    " ",
                ),
            ),
            ("twinpath.settings_hash", self.settings_hash()),
            (
                "twinpath.settings",
                lines(&mut self.settings.iter().map(|(k, v)| (k, v)), " = "),
            ),
            ("twinpath.seed", self.seed.to_string()),
            ("twinpath.sampler", self.sampler.clone()),
            ("twinpath.backend", self.backend.clone()),
            ("twinpath.samples", self.samples.to_string()),
        ];
        if let Some((part, all)) = self.part {
            a.push(("twinpath.part", format!("{part} of {all}")));
        }
        a
    }

    /// Reads the header back from a part file's attributes; `what` names the file in errors.
    fn from_attributes(other: &HashMap<Text, AttributeValue>, what: &Path) -> Result<Self> {
        let get = |name: &str| attribute(other, name, what);
        let format = get("twinpath.format")?;
        if format != FORMAT_VERSION.to_string() {
            bail!(
                "{}: part-file format {format}; this twinpath reads format {FORMAT_VERSION}",
                what.display()
            );
        }
        let pairs = |name: &str, sep: &str| -> Result<Vec<(String, String)>> {
            let v = get(name)?;
            v.lines()
                .filter(|l| !l.is_empty())
                .map(|l| {
                    // Hashes are hex, setting names have no spaces: split at the first `sep`.
                    l.split_once(sep)
                        .map(|(a, b)| (a.to_string(), b.to_string()))
                        .ok_or_else(|| anyhow!("{}: {name}: bad line '{l}'", what.display()))
                })
                .collect()
        };
        let range = |text: &str| {
            SampleRange::parse(text).with_context(|| format!("{}: sample range", what.display()))
        };
        let part = match other.get(&Text::from("twinpath.part")) {
            None => None,
            Some(_) => {
                let v = get("twinpath.part")?;
                let (p, all) = v
                    .split_once(" of ")
                    .ok_or_else(|| anyhow!("{}: twinpath.part '{v}'", what.display()))?;
                Some((Part::parse(p)?, range(all)?))
            }
        };
        let inputs = pairs("twinpath.inputs", " ")?
            .into_iter()
            .map(|(hash, path)| (path, hash))
            .collect();
        let header = Self {
            version: get("twinpath.version")?,
            scene: get("twinpath.scene")?,
            inputs,
            settings: pairs("twinpath.settings", " = ")?,
            seed: number(other, "twinpath.seed", what)? as u32,
            sampler: get("twinpath.sampler")?,
            backend: get("twinpath.backend")?,
            samples: range(&get("twinpath.samples")?)?,
            part,
        };
        if header.scene_hash() != get("twinpath.scene_hash")?
            || header.settings_hash() != get("twinpath.settings_hash")?
        {
            bail!(
                "{}: its header's hashes do not match its file list and settings (edited?)",
                what.display()
            );
        }
        Ok(header)
    }
}

/// The text attribute `name` of a part file's header (`what` names the file in errors).
fn attribute(other: &HashMap<Text, AttributeValue>, name: &str, what: &Path) -> Result<String> {
    match other.get(&Text::from(name)) {
        Some(AttributeValue::Text(t)) => String::from_utf8(t.bytes().to_vec())
            .map_err(|_| anyhow!("{}: attribute {name} is not UTF-8", what.display())),
        Some(_) => bail!("{}: attribute {name} is not text", what.display()),
        None => bail!(
            "{}: not a twinpath part file (no attribute {name})",
            what.display()
        ),
    }
}

/// The number in attribute `name`.
fn number(other: &HashMap<Text, AttributeValue>, name: &str, what: &Path) -> Result<u64> {
    let v = attribute(other, name, what)?;
    v.parse()
        .map_err(|_| anyhow!("{}: {name} '{v}' is not a number", what.display()))
}

/// 32-bit words of a fixed-point sum, and of an f64 sum of squares, per channel.
const SUM_WORDS: usize = 4;
const SQUARE_WORDS: usize = 2;
const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// Writes `film` (the samples of `header.samples`) as a part file at `path`.
pub fn write_part(path: &Path, header: &PartHeader, film: &Film) -> Result<()> {
    let n = film.count.len();
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    let means = film.mean();
    for (c, name) in CHANNELS.iter().enumerate() {
        channels.push(AnyChannel::new(
            *name,
            FlatSamples::F32(means.iter().map(|m| m[c]).collect()),
        ));
        for k in 0..SUM_WORDS {
            let words = film.sum.iter().map(|s| (s[c].0 as u128 >> (32 * k)) as u32);
            channels.push(AnyChannel::new(
                format!("{name}.sum.{k}").as_str(),
                FlatSamples::U32(words.collect()),
            ));
        }
        for k in 0..SQUARE_WORDS {
            let words = film
                .sum_sq
                .iter()
                .map(|s| (s[c].to_bits() >> (32 * k)) as u32);
            channels.push(AnyChannel::new(
                format!("{name}.sumsq.{k}").as_str(),
                FlatSamples::U32(words.collect()),
            ));
        }
    }
    channels.push(AnyChannel::new(
        "count",
        FlatSamples::U32(film.count.clone()),
    ));
    debug_assert!(channels.iter().all(|ch| ch.sample_data.len() == n));
    let mut attributes = LayerAttributes::named("twinpath part");
    let discarded = ("twinpath.discarded", film.discarded.to_string());
    for (name, value) in header.attributes().into_iter().chain([discarded]) {
        attributes.other.insert(
            Text::from(name),
            AttributeValue::Text(Text::from_slice_unchecked(value.as_bytes())),
        );
    }
    let layer = Layer::new(
        (film.width as usize, film.height as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .with_context(|| format!("{}: cannot write the part file", path.display()))
}

/// Reads only the header of the part file at `path`.
pub fn read_part_header(path: &Path) -> Result<PartHeader> {
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .with_context(|| format!("{}: not a readable EXR file", path.display()))?;
    let layer = meta
        .headers
        .first()
        .ok_or_else(|| anyhow!("{}: an EXR file without layers", path.display()))?;
    PartHeader::from_attributes(&layer.own_attributes.other, path)
}

/// Reads the film (image sums only) of the part file at `path`, whose header
/// [`read_part_header`] reads.
pub fn read_part(path: &Path) -> Result<Film> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .with_context(|| format!("{}: not a readable EXR file", path.display()))?;
    let layer = &image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let mut film = Film::new(w as u32, h as u32);
    let channel = |name: &str| -> Result<&[u32]> {
        let ch = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.eq(name))
            .ok_or_else(|| anyhow!("{}: part file without channel {name}", path.display()))?;
        match &ch.sample_data {
            FlatSamples::U32(v) => Ok(v),
            _ => bail!("{}: channel {name} is not 32-bit words", path.display()),
        }
    };
    film.count.copy_from_slice(channel("count")?);
    for (c, name) in CHANNELS.iter().enumerate() {
        for k in 0..SUM_WORDS {
            let words = channel(&format!("{name}.sum.{k}"))?;
            for (s, &w) in film.sum.iter_mut().zip(words) {
                s[c] = FixedSum((s[c].0 as u128 | (w as u128) << (32 * k)) as i128);
            }
        }
        for k in 0..SQUARE_WORDS {
            let words = channel(&format!("{name}.sumsq.{k}"))?;
            for (s, &w) in film.sum_sq.iter_mut().zip(words) {
                s[c] = f64::from_bits(s[c].to_bits() | (w as u64) << (32 * k));
            }
        }
    }
    film.discarded = number(&layer.attributes.other, "twinpath.discarded", path)?;
    Ok(film)
}
