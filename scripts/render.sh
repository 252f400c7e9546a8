#!/usr/bin/env bash
# Renders a scene (default: the built-in Cornell scene) after installing what is missing.
# Arguments go to `twinpath render`, e.g. `scripts/render.sh scenes/cornell.toml --spp 64`.
#
# It builds the whole workspace, as scripts/test.sh does, and runs the binary directly: building
# one package (`cargo run -p twinpath`) resolves the dependencies' features differently and
# would rebuild rust-gpu's compiler backend (several minutes) a second time.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo build --workspace --quiet
exec "${CARGO_TARGET_DIR:-target}/debug/twinpath" render "$@"
