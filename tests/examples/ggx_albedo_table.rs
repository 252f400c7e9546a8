//! Writes `host/src/scene/ggx_albedo_table.rs`, the GGX albedo table of
//! `kernel::bsdf::multiple_scattering`, from `twinpath::scene::ggx_albedo`'s quadrature:
//!
//!     cargo run -p twinpath-tests --example ggx_albedo_table > host/src/scene/ggx_albedo_table.rs
//!
//! (`tests/tests/multiple_scattering.rs` checks the committed file is what this writes.)

fn main() {
    print!("{}", twinpath_tests::ggx_table::source());
}
