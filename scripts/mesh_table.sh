#!/usr/bin/env bash
# Issue 21's table: twinpath's CPU backend against Mitsuba 3 (llvm_ad_rgb, independent and
# ldsampler) on the Cornell room with a generated torus knot of N triangles
# (scripts/knot_scenes.py), time to relMSE 0.002 and 0.0075, from one run of this script.
#   scripts/mesh_table.sh OUTDIR [N ...]        (default N: 10000 100000 1000000)
# Per N: the reference (`twinpath reference`, $REFERENCE_SPP spp, default 4096, CPU), `twinpath
# bench` (Sobol and independent, throughput roulette: the defaults), Mitsuba with both samplers
# against the same reference (scripts/peer_mitsuba.sh), then scripts/time_to_error.py, and the
# BVH's bytes per triangle (`twinpath rays`). Everything lands in OUTDIR; the table is
# OUTDIR/table.txt. Run from the repository root on an otherwise idle machine.
set -euo pipefail
out=${1:?usage: scripts/mesh_table.sh OUTDIR [N ...]}
shift
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(10000 100000 1000000)
bin=${TWINPATH:-target/debug/twinpath}
ref_spp=${REFERENCE_SPP:-4096}
max_spp=${MAX_SPP:-256}
mkdir -p "$out"
python3 scripts/knot_scenes.py "$out/scenes" "${sizes[@]}"
: > "$out/table.txt"
for n in "${sizes[@]}"; do
    scene=$out/scenes/knot_$n.toml
    ref=$out/reference_$n.exr
    [ -f "$ref" ] || "$bin" reference "$scene" --backend cpu --spp "$ref_spp" -o "$ref" 2>&1 | tail -3
    "$bin" bench "$scene" --reference "$ref" --backend cpu --max-spp "$max_spp" \
        --variant "twinpath-sobol:sampler=sobol" \
        --variant "twinpath-independent:sampler=independent" \
        --out-dir "$out/bench_$n" 2>&1 | tail -2
    TWINPATH_PEER_REFERENCE=$ref bash scripts/peer_mitsuba.sh "$out/mitsuba_$n.csv" \
        --max-spp "$max_spp" --mesh "$out/scenes/knot_$n.ply" 2>/dev/null
    TWINPATH_PEER_REFERENCE=$ref bash scripts/peer_mitsuba.sh "$out/mitsuba_ldsampler_$n.csv" \
        --max-spp "$max_spp" --mesh "$out/scenes/knot_$n.ply" --sampler ldsampler 2>/dev/null
    {
        echo "== knot_$n ($(sed -n 's/.*element face \([0-9]*\).*/\1/p' \
            <(head -c 400 "$out/scenes/knot_$n.ply" | tr -c '[:print:]\n' ' ')) triangles)"
        python3 scripts/time_to_error.py --target 0.0075 --target 0.002 \
            "$out/mitsuba_$n.csv" "$out/bench_$n/bench.csv" "$out/mitsuba_ldsampler_$n.csv"
        "$bin" rays "$scene" --repeats 1 2>&1 | grep -E "BVH build|Mrays" || true
    } | tee -a "$out/table.txt"
done
