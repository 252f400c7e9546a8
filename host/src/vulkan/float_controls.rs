//! The 32-bit float controls of a Vulkan device (Vulkan 1.2 core, `VK_KHR_shader_float_controls`)
//! and asking for them: what a device offers, and the kernel's SPIR-V module with the execution
//! modes it offers added, so that such a device keeps denormals, keeps the sign of zero,
//! infinities and NaNs, and rounds to nearest even, as the CPU does.
//!
//! Without them a Vulkan device may flush denormals, lose the sign of zero and round toward
//! zero; the kernel's error bounds assume all of that (docs/robustness.md, "Under Vulkan's
//! arithmetic"), so the controls are not needed for correctness: they bring a device's
//! arithmetic closer to the CPU's. rust-gpu 0.11 has no attribute for these execution modes, nor
//! for the `NoContraction` decoration (which no bound needs: fusing a multiply into an add only
//! removes a rounding), so the modes are added to the module's words when it is loaded.
//!
//! The module's layout (SPIR-V specification 2.4): capabilities first, then extensions, imports,
//! the memory model, entry points, execution modes, and the rest. Float controls are core since
//! SPIR-V 1.4 (the kernel's module is 1.5), so no `OpExtension` is needed.

use ash::vk;

/// What a device offers for 32-bit floats.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FloatControls {
    pub denorm_preserve: bool,
    pub denorm_flush_to_zero: bool,
    pub signed_zero_inf_nan_preserve: bool,
    pub rounding_mode_rte: bool,
    pub rounding_mode_rtz: bool,
    /// Whether 32-bit denormal behaviour may be set apart from the other widths
    /// (`denormBehaviorIndependence` is ALL or 32_BIT_ONLY).
    pub denorm_independent: bool,
    /// Whether the 32-bit rounding mode may be set apart from the other widths.
    pub rounding_independent: bool,
}

/// The execution modes the kernel asks of a device: each one the device offers (for the
/// denormal and rounding modes, only where 32 bits may be set on their own: the module sets no
/// mode for other widths).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Requested {
    pub denorm_preserve: bool,
    pub signed_zero_inf_nan_preserve: bool,
    pub rounding_mode_rte: bool,
}

impl FloatControls {
    /// A device's controls from its `VkPhysicalDeviceFloatControlsProperties`.
    pub fn from_properties(p: &vk::PhysicalDeviceFloatControlsProperties) -> Self {
        let independent = |i: vk::ShaderFloatControlsIndependence| {
            i == vk::ShaderFloatControlsIndependence::ALL
                || i == vk::ShaderFloatControlsIndependence::TYPE_32_ONLY
        };
        Self {
            denorm_preserve: p.shader_denorm_preserve_float32 == vk::TRUE,
            denorm_flush_to_zero: p.shader_denorm_flush_to_zero_float32 == vk::TRUE,
            signed_zero_inf_nan_preserve: p.shader_signed_zero_inf_nan_preserve_float32 == vk::TRUE,
            rounding_mode_rte: p.shader_rounding_mode_rte_float32 == vk::TRUE,
            rounding_mode_rtz: p.shader_rounding_mode_rtz_float32 == vk::TRUE,
            denorm_independent: independent(p.denorm_behavior_independence),
            rounding_independent: independent(p.rounding_mode_independence),
        }
    }

    /// What the kernel asks of this device.
    pub fn requested(&self) -> Requested {
        Requested {
            denorm_preserve: self.denorm_preserve && self.denorm_independent,
            signed_zero_inf_nan_preserve: self.signed_zero_inf_nan_preserve,
            rounding_mode_rte: self.rounding_mode_rte && self.rounding_independent,
        }
    }

    /// The controls as `info` lists them ("none" if it offers none).
    pub fn describe(&self) -> String {
        list(&[
            (self.denorm_preserve, "denormals preserved"),
            (self.denorm_flush_to_zero, "denormals flushed"),
            (
                self.signed_zero_inf_nan_preserve,
                "signed zero/inf/NaN preserved",
            ),
            (self.rounding_mode_rte, "round to nearest even"),
            (self.rounding_mode_rtz, "round toward zero"),
        ])
    }
}

impl Requested {
    /// All three (for tests of the module patch).
    pub const ALL: Requested = Requested {
        denorm_preserve: true,
        signed_zero_inf_nan_preserve: true,
        rounding_mode_rte: true,
    };

    /// The requested modes as `info` lists them ("none" if none).
    pub fn describe(&self) -> String {
        list(&[
            (self.denorm_preserve, "DenormPreserve"),
            (
                self.signed_zero_inf_nan_preserve,
                "SignedZeroInfNanPreserve",
            ),
            (self.rounding_mode_rte, "RoundingModeRTE"),
        ])
    }

    /// (capability, execution mode) of each requested control (SPIR-V 3.2.6 and 3.2.31).
    fn modes(&self) -> Vec<(u32, u32)> {
        [
            (self.denorm_preserve, (4464, 4459)),
            (self.signed_zero_inf_nan_preserve, (4466, 4461)),
            (self.rounding_mode_rte, (4467, 4462)),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|&(_, m)| m)
        .collect()
    }
}

fn list(items: &[(bool, &str)]) -> String {
    let on: Vec<&str> = items.iter().filter(|(b, _)| *b).map(|(_, n)| *n).collect();
    if on.is_empty() {
        "none".to_string()
    } else {
        on.join(", ")
    }
}

const OP_CAPABILITY: u32 = 17;
const OP_ENTRY_POINT: u32 = 15;
const OP_EXECUTION_MODE: u32 = 16;
const OP_EXECUTION_MODE_ID: u32 = 331;
const HEADER_WORDS: usize = 5;

/// `words` (a SPIR-V module) with the `requested` float controls: one `OpCapability` each after
/// the header, and one `OpExecutionMode %entry MODE 32` each for every entry point, after the
/// module's own execution modes. Unchanged if nothing is requested. An error if the words are
/// not a well-formed module (a zero-length instruction, one past the end).
pub fn request(words: &[u32], requested: Requested) -> Result<Vec<u32>, String> {
    let modes = requested.modes();
    if modes.is_empty() {
        return Ok(words.to_vec());
    }
    if words.len() < HEADER_WORDS || words[0] != 0x0723_0203 {
        return Err("not a SPIR-V module".into());
    }
    // One pass over the instructions: the entry points, and where the execution-mode section
    // ends (after the last entry point or execution mode).
    let (mut entries, mut modes_end, mut at) = (Vec::new(), None, HEADER_WORDS);
    while at < words.len() {
        let count = (words[at] >> 16) as usize;
        let opcode = words[at] & 0xffff;
        if count == 0 || at + count > words.len() {
            return Err(format!("malformed instruction at word {at}"));
        }
        match opcode {
            OP_ENTRY_POINT => {
                entries.push(*words.get(at + 2).ok_or("short OpEntryPoint")?);
                modes_end = Some(at + count);
            }
            OP_EXECUTION_MODE | OP_EXECUTION_MODE_ID => modes_end = Some(at + count),
            _ => {}
        }
        at += count;
    }
    let modes_end = modes_end.ok_or("the module has no entry point")?;
    let mut out = Vec::with_capacity(words.len() + 2 * modes.len() * (1 + 2 * entries.len()));
    out.extend_from_slice(&words[..HEADER_WORDS]);
    for &(capability, _) in &modes {
        out.extend_from_slice(&[2 << 16 | OP_CAPABILITY, capability]);
    }
    out.extend_from_slice(&words[HEADER_WORDS..modes_end]);
    for &entry in &entries {
        for &(_, mode) in &modes {
            out.extend_from_slice(&[4 << 16 | OP_EXECUTION_MODE, entry, mode, 32]);
        }
    }
    out.extend_from_slice(&words[modes_end..]);
    Ok(out)
}
