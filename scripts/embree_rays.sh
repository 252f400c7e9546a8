#!/usr/bin/env bash
# Ray throughput of twinpath's CPU traversal against Embree 3 on the same rays, one ray at a time
# and in packets of 16 (rtcIntersect16 / rtcOccluded16), and BVH build time and memory at 10k,
# 100k and 1M triangles. One thread each; see `twinpath rays --help` and scripts/embree_rays.c.
# Usage: scripts/embree_rays.sh OUT.csv [REPEATS]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/embree_rays.sh OUT.csv [REPEATS]}
repeats=${2:-5}
if [ ! -e /usr/include/embree3/rtcore.h ]; then
    ${SUDO:-} apt-get install -y libembree-dev
fi
cargo build --workspace --quiet
mkdir -p target/rays
gcc -O2 -Wall -o target/rays/embree_rays scripts/embree_rays.c -lembree3 -lm
twinpath=${CARGO_TARGET_DIR:-target}/debug/twinpath
rm -f "$out"
run() { # NAME WIDTH [twinpath rays options...]
    local name=$1 width=$2
    shift 2
    # One thread for our BVH build too (Embree builds with threads=1).
    RAYON_NUM_THREADS=1 "$twinpath" rays --width "$width" --repeats "$repeats" --ray-file "target/rays/$name.rays" --csv "$out" "$@"
    target/rays/embree_rays "target/rays/$name.rays" "$name" "$repeats" "$out"
}
run cornell 1024
for n in 10000 100000 1000000; do
    run "knot$((n / 1000))k" 512 --mesh-triangles "$n"
done
