#!/usr/bin/env bash
# Issue 36's table: twinpath's CPU backend at its defaults against its peers on this machine,
# Mitsuba 3 (llvm_ad_rgb, `ldsampler`, its best sampler here; `independent` too with
# MITSUBA_SAMPLERS="ldsampler independent") and Blender's Cycles (bpy from PyPI, CPU, unbiased
# settings), each validated against the reference before it is timed, time to relMSE 0.002, from
# one run. Scenes: `cornell` (scenes/cornell.toml) and `materials` (scenes/cornell_materials.toml)
# against their Mitsuba references in tests/reference/, the Cornell room with a torus knot of N
# triangles (scripts/knot_scenes.py) or the Stanford bunny Loop-subdivided L times (`bunnyL`, 3:
# 235k triangles; scripts/bunny_scene.py, npm) against twinpath's own reference, and `textured`,
# a textured scene built in Blender and exported by its glTF exporter (scripts/textured_room.py;
# twinpath and Cycles only: Mitsuba reads no glTF), against twinpath's own reference.
#   scripts/peer_table.sh OUTDIR [cornell | materials | textured | N | bunnyL ...]
#   (default: cornell materials 10000 100000 1000000 bunny3 textured)
# Per scene: the reference if it has none (`twinpath reference`, $REFERENCE_SPP spp, default
# 4096, CPU); Cycles' validation (two halves of $VALIDATE_SPP spp, default 64, against the
# reference: channel means and block z-scores; scripts/peer_cycles.py); `twinpath bench`,
# Mitsuba and Cycles at 1, 2, 4, ... spp up to $MAX_SPP (default 256; Cycles, the slowest, to
# $CYCLES_MAX_SPP, default 64, and moved to 0.002 at its measured efficiency); then whole
# processes as a user runs them at $WHOLE_SPP spp (default 256; Cycles at $CYCLES_MAX_SPP), timed
# from the shell, each image's time to 0.002 at its efficiency. Everything lands in OUTDIR; the
# table is OUTDIR/table.md (scripts/peer_table.py), the details OUTDIR/details.txt. Run from the
# repository root on an otherwise idle machine; about 40 minutes for the default scenes. The
# binary is $TWINPATH, default target/release/twinpath (`cargo build --release -p twinpath`).
set -euo pipefail
# A scene without Mitsuba's CSVs (textured) lists none.
shopt -s nullglob
out=${1:?usage: scripts/peer_table.sh OUTDIR [cornell | materials | N | bunnyL ...]}
shift
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(cornell materials 10000 100000 1000000 bunny3 textured)
bin=${TWINPATH:-target/release/twinpath}
ref_spp=${REFERENCE_SPP:-4096}
max_spp=${MAX_SPP:-256}
cycles_max_spp=${CYCLES_MAX_SPP:-64}
validate_spp=${VALIDATE_SPP:-64}
whole_spp=${WHOLE_SPP:-256}
read -r -a mitsuba_samplers <<< "${MITSUBA_SAMPLERS:-ldsampler}"

# whole DIR LABEL SPP COMMAND...: runs COMMAND (which writes DIR/whole.exr) and prints its wall
# time, the image's relMSE against $ref, the time to 0.002 at that efficiency and the z of its
# mean difference (flagged beyond 4); appends "LABEL,seconds,relmse,z" to DIR/whole.csv.
whole() {
    local dir=$1 label=$2 spp=$3 t0 t1 e d z
    shift 3
    rm -f "$dir/whole.exr"
    t0=$(date +%s.%N)
    "$@" > /dev/null 2>&1
    t1=$(date +%s.%N)
    d=$("$bin" diff "$dir/whole.exr" "$ref")
    e=$(awk '$1 == "relmse" {print $2}' <<< "$d")
    z=$(awk '$1 == "mean_diff_z" {print $2}' <<< "$d")
    echo "$label,$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }'),$e,$z" >> "$dir/whole.csv"
    # z: the image's mean difference from the reference over its standard error; a peer beyond
    # 4 renders another image (Mitsuba's ldsampler: docs/performance.md) and is flagged.
    awk -v l="$label" -v a="$t0" -v b="$t1" -v e="$e" -v s="$spp" -v z="$z" 'BEGIN {
        printf "  %-34s %7.2f s for %d spp, relMSE %.5f -> %6.2f s to 0.002, z %+.1f%s\n",
            l, b - a, s, e, (b - a) * e / 0.002, z, (z > 4 || z < -4) ? " ANOTHER IMAGE" : "" }'
}
mkdir -p "$out"
: > "$out/details.txt"
for key in "${scenes[@]}"; do
    dir=$out/$key
    mkdir -p "$dir"
    rm -f "$dir/whole.csv"
    peer=() # the peers' scene options
    triangles=0 # of meshes (the spheres are not)
    case $key in
        cornell)
            scene=scenes/cornell.toml
            ref=tests/reference/cornell_spheres/mitsuba_ref.exr ;;
        materials)
            scene=scenes/cornell_materials.toml
            ref=tests/reference/cornell_materials/mitsuba_ref.exr
            peer=(--scene materials) ;;
        textured)
            # Built in Blender and exported by its glTF exporter (scripts/textured_room.py):
            # twinpath renders the file, Cycles the scene it came from; Mitsuba has no glTF
            # loader and sits this one out.
            peer=(--scene textured)
            bash scripts/peer_cycles.sh - "${peer[@]}" --export-gltf "$dir/scene.glb" \
                --size 256 256 > /dev/null
            scene=$dir/textured.toml
            printf '[camera]\ngltf = "camera"\nwidth = 256\nheight = 256\n[[gltf]]\nfile = "scene.glb"\n' \
                > "$scene"
            ref=$dir/reference.exr
            [ -f "$ref" ] || "$bin" reference "$scene" --backend cpu --spp "$ref_spp" -o "$ref" 2>&1 \
                | tail -1
            triangles=$("$bin" render "$scene" --backend cpu --spp 1 -o "$dir/count.exr" 2>&1 \
                | sed -n 's/.* \([0-9]*\) triangles.*/\1/p' | head -1) ;;
        bunny*)
            name=$(python3 scripts/bunny_scene.py "$dir" "${key#bunny}")
            scene=$dir/$name.toml ;;
        *)
            python3 scripts/knot_scenes.py "$dir" "$key" > /dev/null
            scene=$dir/knot_$key.toml ;;
    esac
    if [ "$key" != cornell ] && [ "$key" != materials ] && [ "$key" != textured ]; then
        ply=${scene%.toml}.ply
        peer=(--mesh "$ply")
        triangles=$(sed -n 's/.*element face \([0-9]*\).*/\1/p' \
            <(head -c 400 "$ply" | tr -c '[:print:]\n' ' '))
        ref=$dir/reference.exr
        [ -f "$ref" ] || "$bin" reference "$scene" --backend cpu --spp "$ref_spp" -o "$ref" 2>&1 \
            | tail -1
    fi
    echo "$triangles" > "$dir/triangles"
    {
        echo "== $key ($triangles triangles; reference $ref)"
        TWINPATH_PEER_REFERENCE=$ref bash scripts/peer_cycles.sh "$dir/cycles_validate.exr" \
            "${peer[@]}" --validate "$validate_spp"
    } | tee -a "$out/details.txt"
    "$bin" bench "$scene" --reference "$ref" --backend cpu --max-spp "$max_spp" \
        --variant "twinpath:sampler=sobol" --out-dir "$dir/bench" 2>&1 | tail -1
    samplers=("${mitsuba_samplers[@]}")
    [ "$key" != textured ] || samplers=()
    for sampler in "${samplers[@]}"; do
        TWINPATH_PEER_REFERENCE=$ref bash scripts/peer_mitsuba.sh "$dir/mitsuba_$sampler.csv" \
            --max-spp "$max_spp" --sampler "$sampler" "${peer[@]}" > /dev/null 2>&1
    done
    TWINPATH_PEER_REFERENCE=$ref bash scripts/peer_cycles.sh "$dir/cycles.csv" \
        --max-spp "$cycles_max_spp" "${peer[@]}" > /dev/null 2>&1
    {
        python3 scripts/time_to_error.py --target 0.002 "$dir"/mitsuba_*.csv \
            "$dir/bench/bench.csv" "$dir/cycles.csv"
        echo "whole processes (wall time from the shell, load and set-up included):"
        # Seed 2: `twinpath reference` renders its first half with the scene's seed (1), whose
        # first samples a render at seed 1 would repeat (its error against the reference then
        # reads 12% low at 256 of 4096 spp).
        whole "$dir" twinpath "$whole_spp" "$bin" render "$scene" --backend cpu --seed 2 \
            --spp "$whole_spp" --quiet -o "$dir/whole.exr"
        for sampler in "${samplers[@]}"; do
            whole "$dir" "mitsuba-$sampler" "$whole_spp" env TWINPATH_PEER_REFERENCE="$ref" \
                bash scripts/peer_mitsuba.sh "$dir/whole.exr" --once "$whole_spp" \
                --sampler "$sampler" "${peer[@]}"
        done
        whole "$dir" cycles "$cycles_max_spp" env TWINPATH_PEER_REFERENCE="$ref" \
            bash scripts/peer_cycles.sh "$dir/whole.exr" --once "$cycles_max_spp" "${peer[@]}"
    } | tee -a "$out/details.txt"
done
python3 scripts/peer_table.py "$out" "${scenes[@]}" | tee "$out/table.md"
