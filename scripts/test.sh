#!/usr/bin/env bash
# Runs every twinpath test: installs what is missing (scripts/setup.sh), then formatting,
# clippy (warnings are errors), and the whole test suite (kernel properties, samplers,
# closed-form scenes, the Mitsuba comparison, scene errors, the SPIR-V module).
# One build profile (dev, optimised) serves tests and renders alike.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
cargo test --workspace -- --nocapture "$@"
