# Sourced by the scripts that run Python with Mitsuba 3 (peer_mitsuba.sh, variance_by_depth.sh):
# sets $venv to their shared virtualenv, creating it on first use.
venv=target/peer-mitsuba-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q mitsuba numpy
fi
