# Sourced by the scripts that run Blender's Cycles through bpy (cycles_fixtures.sh,
# peer_cycles.sh): sets $venv to their shared virtualenv, creating it on first use. Blender 5.3
# as a Python module (`bpy` from PyPI) needs Python 3.13; $PYTHON313 names one, else the first
# of python3.13 and pyenv's 3.13.0 that runs.
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
    [ -n "$python" ] || { echo "needs Python 3.13 for bpy (set PYTHON313)" >&2; exit 1; }
    "$python" -m venv "$venv"
    "$venv/bin/pip" install -q bpy numpy
fi
