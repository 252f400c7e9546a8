#!/usr/bin/env bash
# Runs every twinpath test: installs what is missing (scripts/setup.sh), then formatting,
# clippy (warnings are errors), the whole test suite (samplers, closed-form scenes, the Mitsuba
# comparison, CPU-vs-GPU equivalence on lavapipe, numerical robustness, scene errors, the SPIR-V
# module and the shipped module's manifest, render parts and their merge), the Slurm scripts on
# a one-node cluster, and the CPU-only build (no `gpu` feature). CI (.ci/run) adds a bounded
# fuzzing run of the parsers (scripts/fuzz.sh) and the byte-for-byte check of the shipped kernel
# module (scripts/build_kernel.sh --check).
# One build profile (dev, optimised) serves tests and renders alike.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
mkdir -p target
cargo test --workspace -- --nocapture "$@" 2>&1 | tee target/test.log
# The Slurm job-array scripts on a one-node Slurm cluster started for the test (scripts/slurm/).
bash scripts/slurm/test_cluster.sh target/debug/twinpath 2>&1 | tee -a target/test.log
# The CPU-only build: without the `gpu` feature the workspace still builds the whole CLI, which
# renders on the CPU backend and says the GPU backend is not built. Then the default build again,
# so target/debug/twinpath is the full binary (the CPU-only twinpath compiles once, ~2 minutes on
# two cores; the second build only relinks the cached default one).
cargo build --workspace --no-default-features
target/debug/twinpath info | grep -q '^gpu backend: not built'
target/debug/twinpath render --backend auto --spp 2 --width 32 --quiet -o target/cpu_only.exr
cargo build --workspace
echo "cpu-only build: twinpath rendered target/cpu_only.exr without the gpu feature" | tee -a target/test.log
# One closing line with the totals of every cargo test binary above.
awk '/^test result:/ { p += $4; f += $6 } END { printf "tests: %d passed, %d failed\n", p, f }' target/test.log
