//! Shared access to the Vulkan device for the GPU tests: one context per test binary, with the
//! validation layers on, and a check that they reported nothing.

use std::sync::{Mutex, OnceLock};
use twinpath::vulkan::device::{Context, VALIDATION_ERRORS, VALIDATION_WARNINGS};

/// The test binary's Vulkan context (validation on, see [`crate::validation_wanted`]). Tests
/// take the lock in turn.
pub fn context() -> &'static Mutex<Context> {
    static CTX: OnceLock<Mutex<Context>> = OnceLock::new();
    CTX.get_or_init(|| {
        Mutex::new(
            Context::new(None, crate::validation_wanted())
                .expect("a Vulkan ray-tracing device (lavapipe: scripts/setup.sh installs it)"),
        )
    })
}

/// Asserts that the validation layers have reported no error and no warning so far.
pub fn assert_validation_clean() {
    let errors = VALIDATION_ERRORS.load(std::sync::atomic::Ordering::SeqCst);
    let warnings = VALIDATION_WARNINGS.load(std::sync::atomic::Ordering::SeqCst);
    assert_eq!(
        (errors, warnings),
        (0, 0),
        "validation layers reported errors/warnings (printed above)"
    );
}

/// Whether the test device computes with IEEE-754 arithmetic as the CPU does
/// ([`is_ieee_device`] of the test binary's context).
pub fn device_is_ieee() -> bool {
    is_ieee_device(&context().lock().unwrap())
}

/// Whether `ctx`'s device computes with IEEE-754 arithmetic as the CPU does (lavapipe: LLVM's
/// code for the host CPU), so that the two backends give the same numbers. Any other device is
/// of the Vulkan class: its arithmetic is only what the specification allows, and equivalence
/// is stated within the bounds derived for it (`docs/robustness.md`, "Under Vulkan's
/// arithmetic") and in distribution.
pub fn is_ieee_device(ctx: &Context) -> bool {
    ctx.device_name.starts_with("llvmpipe")
}
