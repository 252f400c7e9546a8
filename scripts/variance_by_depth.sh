#!/usr/bin/env bash
# Variance part of the Cornell image's relMSE by path depth and sampler (two seeds each):
# scripts/variance_by_depth.py in the virtualenv of scripts/peer_mitsuba.sh (it reads EXR with
# Mitsuba's Bitmap). Usage: scripts/variance_by_depth.sh [SPP]   (default 16)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mitsuba_venv.sh
cargo build -q -p twinpath
"$venv/bin/python" scripts/variance_by_depth.py target/debug/twinpath \
    tests/reference/cornell_spheres/mitsuba_ref.exr "${1:-16}"
