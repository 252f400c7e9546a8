//! The glTF loader on arbitrary bytes (.glb or JSON): an error or a scene, never a panic, never
//! unbounded memory (run with -rss_limit_mb). External buffers and images are refused (no
//! folder), so the fuzzer reads no files.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = twinpath::scene::gltf::load_bytes(std::path::Path::new("fuzz.glb"), data, None, None);
});
