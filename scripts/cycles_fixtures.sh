#!/usr/bin/env bash
# Regenerates the Cycles fixtures of tests/tests/cycles.rs (tests/reference/cycles/<scene>/):
# Blender 5.3 as a Python module (`bpy` from PyPI, which needs Python 3.13) in a virtualenv,
# then scripts/cycles_fixtures.py. About 12 s per scene on 2 cores.
# Usage: scripts/cycles_fixtures.sh [SCENE ...]   (default: every scene)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/cycles_venv.sh
"$venv/bin/python" scripts/cycles_fixtures.py tests/reference/cycles "$@"
