#!/usr/bin/env bash
# A Mitsuba 3 reference (scripts/mitsuba_reference.py) in the shared virtualenv.
# Usage: scripts/mitsuba_reference.sh SCENE OUTDIR [--spp N] [--chunk N] [--variant V]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mitsuba_venv.sh
llvm=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
if [ ! -e "$llvm" ]; then
    ${SUDO:-} apt-get install -y libllvm19
fi
DRJIT_LIBLLVM_PATH=$llvm "$venv/bin/python" scripts/mitsuba_reference.py "$@"
