//! Shared access to the Vulkan device for the GPU tests: one context per test binary, with the
//! validation layers on, and a check that they reported nothing.

use std::sync::{Mutex, OnceLock};
use twinpath::vulkan::device::{Context, VALIDATION_ERRORS, VALIDATION_WARNINGS};

/// The test binary's Vulkan context (validation on). Tests take the lock in turn.
pub fn context() -> &'static Mutex<Context> {
    static CTX: OnceLock<Mutex<Context>> = OnceLock::new();
    CTX.get_or_init(|| {
        Mutex::new(
            Context::new(None, true)
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
