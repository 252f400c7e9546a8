//! How a glTF file's `KHR_lights_punctual` intensities (candela, lux) read as twinpath's
//! radiometric units, in each of the conventions Blender's glTF exporter writes.

/// Lumens per watt of the conversion between photometric and radiometric units that Blender's
/// glTF exporter and importer use (`PBR_WATTS_TO_LUMENS`: the luminous efficacy of 555 nm
/// light, the candela's definition), so that a Blender scene's watts survive the round trip.
pub const LUMENS_PER_WATT: f32 = 683.0;

/// How a file's `KHR_lights_punctual` intensities read as twinpath's radiometric units: radiant
/// intensity (W/sr) for point and spot lights, irradiance (W/m^2) for directional ones. Named
/// after the lighting modes of Blender's glTF exporter, which writes each of them (docs/gltf.md,
/// "Light units").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightUnits {
    /// The specification's units (Blender's "Standard", its default): candela and lux, divided
    /// by [`LUMENS_PER_WATT`]. A 100 W Blender point light (written as 100 / 4 pi x 683 cd) is
    /// a light of 100 W.
    #[default]
    Standard,
    /// Blender's "Unitless": the values are radiant intensity and irradiance already (the
    /// exporter wrote W / 4 pi and W/m^2).
    Unitless,
    /// Blender's "Raw": point and spot values are Blender's watts (radiant intensity W / 4 pi),
    /// directional ones W/m^2.
    Raw,
}

impl LightUnits {
    /// The names a TOML scene gives them (`[[gltf]] light_units`).
    pub const NAMES: [&'static str; 3] = ["standard", "unitless", "raw"];

    /// The units named `name` (one of [`LightUnits::NAMES`]).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "standard" => Some(Self::Standard),
            "unitless" => Some(Self::Unitless),
            "raw" => Some(Self::Raw),
            _ => None,
        }
    }

    /// The radiometric value of a file's `intensity` for a light that is `directional` or not.
    pub fn radiometric(self, intensity: f32, directional: bool) -> f32 {
        match self {
            Self::Standard => intensity / LUMENS_PER_WATT,
            Self::Unitless => intensity,
            Self::Raw if directional => intensity,
            Self::Raw => intensity / (4.0 * std::f32::consts::PI),
        }
    }
}
