#!/usr/bin/env bash
# Blender's Cycles (bpy from PyPI, CPU) on the Cornell scene, time against error:
# scripts/peer_cycles.py in the virtualenv of scripts/cycles_venv.sh.
# Usage: scripts/peer_cycles.sh OUT.csv [--max-spp N] [--max-seconds S] [--pattern P]
#        [--mesh MESH.ply] [--once SPP] [--validate SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/peer_cycles.sh OUT.csv [options]}
shift
source scripts/cycles_venv.sh
# The reference image: Mitsuba's converged Cornell render, or $TWINPATH_PEER_REFERENCE (the
# mesh scenes of scripts/peer_table.sh).
reference=${TWINPATH_PEER_REFERENCE:-tests/reference/cornell_spheres/mitsuba_ref.exr}
# Blender prints a line per tile and sample; the script's own lines are kept.
"$venv/bin/python" scripts/peer_cycles.py "$reference" "$out" "$@" 2>&1 \
    | { grep -v -E "^(Fra:|Saved:|Time:)|DeprecationWarning|use_nodes = True" || true; }
