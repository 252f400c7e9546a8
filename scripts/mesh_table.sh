#!/usr/bin/env bash
# Issue 21's table: twinpath's CPU backend against Mitsuba 3 (llvm_ad_rgb, independent and
# ldsampler) on the Cornell room with a generated torus knot of N triangles
# (scripts/knot_scenes.py) or the Stanford bunny Loop-subdivided L times (`bunnyL`, 3: 235k
# triangles; scripts/bunny_scene.py, npm), time to relMSE 0.002 and 0.0075, from one run.
#   scripts/mesh_table.sh OUTDIR [N | bunnyL ...]  (default: 10000 100000 1000000 bunny3)
# Per scene: the reference (`twinpath reference`, $REFERENCE_SPP spp, default 4096, CPU), `twinpath
# bench` (Sobol and independent, throughput roulette: the defaults), Mitsuba with both samplers
# against the same reference (scripts/peer_mitsuba.sh), then scripts/time_to_error.py, and the
# BVH's bytes per triangle (`twinpath rays`); then whole processes as a user runs them, at
# $WHOLE_SPP spp (default 256): `twinpath render` and Mitsuba (`peer_mitsuba.py --once`, both
# samplers) timed from the shell, each image's relMSE, and its time to 0.002 at the same
# efficiency (seconds x relMSE / 0.002). Everything lands in OUTDIR; the table is
# OUTDIR/table.txt. Run from the repository root on an otherwise idle machine.
set -euo pipefail
out=${1:?usage: scripts/mesh_table.sh OUTDIR [N | bunnyL ...]}
shift
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(10000 100000 1000000 bunny3)
bin=${TWINPATH:-target/debug/twinpath}
ref_spp=${REFERENCE_SPP:-4096}
max_spp=${MAX_SPP:-256}
whole_spp=${WHOLE_SPP:-256}

# whole LABEL COMMAND...: runs COMMAND (which writes $out/whole.exr) and prints its wall time,
# the image's relMSE against $ref and the time to 0.002 at that efficiency.
whole() {
    local label=$1 t0 t1 e
    shift
    rm -f "$out/whole.exr"
    t0=$(date +%s.%N)
    "$@" > /dev/null 2>&1
    t1=$(date +%s.%N)
    e=$("$bin" diff "$out/whole.exr" "$ref" | awk '$1 == "relmse" {print $2}')
    awk -v l="$label" -v a="$t0" -v b="$t1" -v e="$e" -v s="$whole_spp" 'BEGIN {
        printf "  %-34s %7.2f s for %d spp, relMSE %.5f -> %6.2f s to 0.002\n",
            l, b - a, s, e, (b - a) * e / 0.002 }'
}
mkdir -p "$out"
: > "$out/table.txt"
for size in "${sizes[@]}"; do
    # n: the files' key (the knot's triangle count, or bunny_T); name: the scene's.
    if [[ $size == bunny* ]]; then
        n=$(python3 scripts/bunny_scene.py "$out/scenes" "${size#bunny}")
        name=$n
    else
        python3 scripts/knot_scenes.py "$out/scenes" "$size"
        n=$size
        name=knot_$n
    fi
    scene=$out/scenes/$name.toml
    ply=$out/scenes/$name.ply
    ref=$out/reference_$n.exr
    [ -f "$ref" ] || "$bin" reference "$scene" --backend cpu --spp "$ref_spp" -o "$ref" 2>&1 \
        | tail -3
    "$bin" bench "$scene" --reference "$ref" --backend cpu --max-spp "$max_spp" \
        --variant "twinpath-sobol:sampler=sobol" \
        --variant "twinpath-independent:sampler=independent" \
        --out-dir "$out/bench_$n" 2>&1 | tail -2
    TWINPATH_PEER_REFERENCE=$ref bash scripts/peer_mitsuba.sh "$out/mitsuba_$n.csv" \
        --max-spp "$max_spp" --mesh "$ply" 2>/dev/null
    TWINPATH_PEER_REFERENCE=$ref bash scripts/peer_mitsuba.sh "$out/mitsuba_ldsampler_$n.csv" \
        --max-spp "$max_spp" --mesh "$ply" --sampler ldsampler 2>/dev/null
    {
        echo "== $name ($(sed -n 's/.*element face \([0-9]*\).*/\1/p' \
            <(head -c 400 "$ply" | tr -c '[:print:]\n' ' ')) triangles)"
        python3 scripts/time_to_error.py --target 0.0075 --target 0.002 \
            "$out/mitsuba_$n.csv" "$out/bench_$n/bench.csv" "$out/mitsuba_ldsampler_$n.csv"
        "$bin" rays "$scene" --repeats 1 2>&1 | grep -E "BVH build|Mrays" || true
        echo "whole processes (wall time from the shell, load and set-up included):"
        whole "twinpath render (Sobol, CPU)" "$bin" render "$scene" --backend cpu \
            --spp "$whole_spp" --quiet -o "$out/whole.exr"
        for sampler in independent ldsampler; do
            whole "mitsuba llvm_ad_rgb $sampler" env TWINPATH_PEER_REFERENCE="$ref" \
                bash scripts/peer_mitsuba.sh "$out/whole.exr" --once "$whole_spp" \
                --mesh "$ply" --sampler "$sampler"
        done
    } | tee -a "$out/table.txt"
done
