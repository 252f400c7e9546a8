#!/usr/bin/env bash
# Renders a scene (default: the built-in Cornell scene) after installing what is missing.
# Arguments go to `twinpath render`, e.g. `scripts/render.sh scenes/cornell.toml --spp 64`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo run --quiet -p twinpath -- render "$@"
