//! The TOML scene parser on arbitrary bytes: an error or a scene, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        // Mesh paths resolve under a directory that does not exist: no file system effects.
        let _ = twinpath::scene::parse_scene(text, std::path::Path::new("/nonexistent/fuzz.toml"));
    }
});
