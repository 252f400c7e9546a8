#!/usr/bin/env bash
# Mitsuba 3 (PyPI) on the Cornell scene, time against error: scripts/peer_mitsuba.py in a venv.
# Usage: scripts/peer_mitsuba.sh OUT.csv [--max-spp N] [--max-seconds S] [--variant llvm_ad_rgb]
#        [--sampler S] [--mesh KNOT.ply]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/peer_mitsuba.sh OUT.csv [options]}
shift
source scripts/mitsuba_venv.sh
# Dr.Jit's LLVM back end fails on Debian's libLLVM 14/15 ("Cannot select: fmaximum").
llvm=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
if [ ! -e "$llvm" ]; then
    ${SUDO:-} apt-get install -y libllvm19
fi
# The reference image: Mitsuba's converged Cornell render, or $TWINPATH_PEER_REFERENCE (for the
# mesh scenes of scripts/peer_table.sh).
reference=${TWINPATH_PEER_REFERENCE:-tests/reference/cornell_spheres/mitsuba_ref.exr}
DRJIT_LIBLLVM_PATH=$llvm "$venv/bin/python" scripts/peer_mitsuba.py "$reference" "$out" "$@"
