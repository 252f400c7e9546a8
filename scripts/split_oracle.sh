#!/usr/bin/env bash
# The most that splitting and roulette at path vertices 1 and 2 could gain on a scene, with each
# pixel's variances known exactly (issue 36; docs/performance.md, "Splitting where it pays").
# Builds the CPU renderer with scripts/split_oracle.patch in a throwaway worktree (its numbers
# fork after vertex 1 or 2: renders with FORK_ID 0 and 1 share each path up to there), renders
# K one-sample images per seed three ways (unforked, forked after vertex 1, after vertex 2; the
# independent sampler, one path at a time), times the scene at its defaults cut after 1 and 2
# vertices and whole (the cost of each part of a sample, best of three), and runs
# scripts/split_oracle.py in the virtualenv of scripts/peer_mitsuba.sh. Then renders the whole
# splits at vertex 1 it learned per tile with the scene's Sobol numbers and compares them with
# unsplit renders at equal time (scripts/split_sobol.py).
# Usage: scripts/split_oracle.sh SCENE REFERENCE.exr [K]   (K default 160)
set -euo pipefail
cd "$(dirname "$0")/.."
scene=$(realpath "${1:?usage: scripts/split_oracle.sh SCENE REFERENCE.exr [K]}")
reference=$(realpath "${2:?usage: scripts/split_oracle.sh SCENE REFERENCE.exr [K]}")
k=${3:-160}
source scripts/mitsuba_venv.sh
root=$PWD
work=$(mktemp -d)
trap 'git -C "$root" worktree remove --force "$work/tree" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git worktree add -q --detach "$work/tree" HEAD
git -C "$work/tree" apply "$root/scripts/split_oracle.patch"
CARGO_TARGET_DIR="$root/target/split_oracle" cargo build -q --release -p twinpath \
    --no-default-features --manifest-path "$work/tree/Cargo.toml"
bin="$root/target/split_oracle/release/twinpath"
mkdir -p "$work/images"
one_path=(--backend cpu --spp 1 --set sampler=independent --set packets=off)
for seed in $(seq 1 "$k"); do
    FORK_LEVEL=0 "$bin" render "$scene" "${one_path[@]}" --seed "$seed" -o "$work/images/a_$seed.exr" >/dev/null 2>&1
    for level in 1 2; do
        FORK_LEVEL=$level FORK_ID=1 "$bin" render "$scene" "${one_path[@]}" --seed "$seed" \
            -o "$work/images/b${level}_$seed.exr" >/dev/null 2>&1
    done
done
best_render_time() {
    local best=
    for _ in 1 2 3; do
        t=$("$bin" render "$scene" --backend cpu --spp 64 "$@" -o "$work/t.exr" 2>&1 |
            sed -n 's/.*render \([0-9.]*\) s.*/\1/p')
        best=$(python3 -c "print(min(float('$t'), float('${best:-inf}')))")
    done
    echo "$best"
}
t1=$(best_render_time --set max_depth=1)
t2=$(best_render_time --set max_depth=2)
t=$(best_render_time)
echo "render time at 64 spp, best of three: cut after vertex 1 $t1 s, after vertex 2 $t2 s, whole $t s"
"$venv/bin/python" scripts/split_oracle.py "$work/images" "$k" "$t1" "$t2" "$t" "$reference" \
    "$work/tiles.txt"
# The learned whole splits at vertex 1 with Sobol's numbers (the scene's own sampler, one path
# at a time): three seeds, continuations 0-3 at 64 spp, unsplit at 64, 128 and 256 spp.
width=$("$bin" render "$scene" --backend cpu --spp 1 -o "$work/t.exr" 2>&1 |
    sed -n 's/.*(\([0-9]*\)x[0-9]*,.*/\1/p' | head -1)
mkdir -p "$work/sobol"
for seed in 11 12 13; do
    for id in 0 1 2 3; do
        FORK_WIDTH=$width FORK_TILES="$work/tiles.txt" FORK_ID=$id "$bin" render "$scene" \
            --backend cpu --spp 64 --seed "$seed" --set packets=off \
            -o "$work/sobol/s${seed}_j$id.exr" >/dev/null 2>&1
    done
    for spp in 64 128 256; do
        "$bin" render "$scene" --backend cpu --spp "$spp" --seed "$seed" --set packets=off \
            -o "$work/sobol/s${seed}_u$spp.exr" >/dev/null 2>&1
    done
done
"$venv/bin/python" scripts/split_sobol.py "$work/sobol" "$work/tiles.txt" "$reference" \
    "$(python3 -c "print($t1 / $t)")" 64 11,12,13
