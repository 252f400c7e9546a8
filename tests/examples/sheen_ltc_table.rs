//! Writes `host/src/scene/sheen_ltc_table.rs`, the sheen table of `kernel::bsdf::sheen`, from
//! the fibre layer's physics (`twinpath_tests::sheen_fit`; a few minutes on two cores):
//!
//! ```text
//! cargo run --release -p twinpath-tests --example sheen_ltc_table > host/src/scene/sheen_ltc_table.rs
//! ```
//!
//! (`tests/tests/sheen.rs` checks sampled nodes of the committed file against this.)

fn main() {
    print!("{}", twinpath_tests::sheen_fit::source());
}
