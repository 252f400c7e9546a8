#!/usr/bin/env bash
# Regenerates the Cycles fixtures of tests/tests/cycles.rs (tests/reference/cycles/<scene>/):
# Blender 5.3 as a Python module (`bpy` from PyPI, which needs Python 3.13) in a virtualenv,
# then scripts/cycles_fixtures.py. About 12 s per scene on 2 cores.
# Usage: scripts/cycles_fixtures.sh [SCENE ...]   (default: every scene)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/cycles-venv
if [ ! -x "$venv/bin/python" ]; then
    python=${PYTHON313:-}
    if [ -z "$python" ]; then
        # The first that runs and is 3.13 (a pyenv shim exists even where it cannot run).
        for p in python3.13 "$HOME/.pyenv/versions/3.13.0/bin/python"; do
            if "$p" -c 'import sys; assert sys.version_info[:2] == (3, 13)' >/dev/null 2>&1; then
                python=$p; break
            fi
        done
    fi
    [ -n "$python" ] || { echo "cycles_fixtures: needs Python 3.13 (set PYTHON313)" >&2; exit 1; }
    "$python" -m venv "$venv"
    "$venv/bin/pip" install -q bpy numpy
fi
"$venv/bin/python" scripts/cycles_fixtures.py tests/reference/cycles "$@"
