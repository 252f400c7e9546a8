//! The PLY loader on arbitrary bytes: an error or triangles, never a panic, never unbounded
//! memory (run with -rss_limit_mb).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = twinpath::scene::mesh::parse_ply(std::path::Path::new("fuzz.ply"), data);
});
