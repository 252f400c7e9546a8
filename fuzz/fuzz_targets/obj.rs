//! The OBJ loader (tobj) on arbitrary bytes: an error or triangles, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = twinpath::scene::mesh::parse_obj(std::path::Path::new("fuzz.obj"), data);
});
