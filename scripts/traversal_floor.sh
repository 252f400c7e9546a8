#!/usr/bin/env bash
# Where a sample's time goes, twinpath's CPU backend against Mitsuba 3 (llvm_ad_rgb, the `path`
# integrator of scripts/peer_mitsuba.py), on the mesh scenes of scripts/peer_table.sh: one render
# each under `perf record` (cpu-clock, both threads), with
#   - the rays traced per sample: twinpath counts its own (`twinpath render` prints them),
#     Mitsuba's are counted by scripts/embree_ray_count.c, preloaded over its Embree calls;
#   - the CPU seconds in ray traversal: twinpath's BVH functions, Mitsuba's Embree traversal
#     (and its sphere shapes' intersection callbacks);
#   - hence each side's traversal rate in rays per CPU second, and the share of the process.
# The last column is the floor the goal of issue 21 meets: to reach relMSE 0.002 in 0.5x
# Mitsuba's time with E times its error per sample (E from the mesh table, given as
# ERROR_RATIO, default 0.82), twinpath may spend 0.5 / E of Mitsuba's process per sample; the
# column says how many times Embree's rate twinpath's traversal would need if everything else in
# its sample stayed as it is.
#   scripts/traversal_floor.sh OUTDIR SPP [N | bunnyL | cornell ...]
# (default: 10000 100000 1000000 bunny3; `cornell`: scenes/cornell.toml and Mitsuba's spheres)
# Needs perf (Debian's linux-perf); run from the repository root on an otherwise idle machine.
set -euo pipefail
out=${1:?usage: scripts/traversal_floor.sh OUTDIR SPP [N | bunnyL | cornell ...]}
spp=${2:?usage: scripts/traversal_floor.sh OUTDIR SPP [N | bunnyL | cornell ...]}
shift 2
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(10000 100000 1000000 bunny3)
bin=${TWINPATH:-target/debug/twinpath}
error_ratio=${ERROR_RATIO:-0.82}
mkdir -p "$out"
shim=$PWD/target/embree_ray_count.so
cc -O2 -shared -fPIC -o "$shim" scripts/embree_ray_count.c -ldl
source scripts/mitsuba_venv.sh
llvm=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
[ -e "$llvm" ] || ${SUDO:-} apt-get install -y libllvm19

# samples PERF_DATA PATTERN: "total matching" perf samples, matching by `dso symbol`.
samples() {
    perf report -i "$1" --no-children --stdio -n --sort dso,sym -g none 2>/dev/null \
        | awk -v p="$2" '!/^#/ && NF > 2 { t += $2; if ($0 ~ p) m += $2 } END { print t, m + 0 }'
}
twinpath_traversal='SmallScene>::closest|SmallScene>::occluded|closest_packet|occluded_packet|closest_in|any_in|closest_of_lane|closest_hit|any_hit'
mitsuba_traversal='Intersector|intersect16|occluded16|intersect8|occluded8|ray_intersect_preliminary_impl|ray_test_impl|embree_intersect|embree_occluded'
rate=2000 # perf samples per CPU second

printf "%-14s %-9s %9s %11s %11s %9s %11s %9s\n" scene renderer "rays/spl" "process s" \
    "travers. s" "share" "Mrays/cpu-s" "floor x" | tee "$out/floor.txt"
for size in "${sizes[@]}"; do
    mesh=()
    if [ "$size" = cornell ]; then
        name=cornell
        mkdir -p "$out/scenes"
        cp scenes/cornell.toml "$out/scenes/cornell.toml"
    elif [[ $size == bunny* ]]; then
        name=$(python3 scripts/bunny_scene.py "$out/scenes" "${size#bunny}")
    else
        python3 scripts/knot_scenes.py "$out/scenes" "$size" > /dev/null
        name=knot_$size
    fi
    scene=$out/scenes/$name.toml
    [ "$name" = cornell ] || mesh=(--mesh "$out/scenes/$name.ply")
    perf record -q -e cpu-clock -F "$rate" -o "$out/$name.twinpath.perf" "$bin" render "$scene" \
        --backend cpu --spp "$spp" --width 256 --height 256 --quiet -o "$out/$name.twinpath.exr" \
        2> "$out/$name.twinpath.log"
    t_rays=$(sed -n 's/.*rays: \([0-9.]*\) per sample.*/\1/p' "$out/$name.twinpath.log")
    # Mitsuba's image is compared with twinpath's (only to satisfy --once; the error is unused).
    LD_PRELOAD=$shim DRJIT_LIBLLVM_PATH=$llvm perf record -q -e cpu-clock -F "$rate" \
        -o "$out/$name.mitsuba.perf" "$venv/bin/python" scripts/peer_mitsuba.py \
        "$out/$name.twinpath.exr" "$out/$name.mitsuba.exr" --once "$spp" "${mesh[@]}" \
        --sampler ldsampler > "$out/$name.mitsuba.log" 2>&1
    m_rays=$(awk '$1 == "samples" { n = $2 } $1 == "embree" { gsub(",", ""); r = $4 + $6 }
        END { printf "%.4f", r / n }' "$out/$name.mitsuba.log")
    read -r t_total t_trav < <(samples "$out/$name.twinpath.perf" "$twinpath_traversal")
    read -r m_total m_trav < <(samples "$out/$name.mitsuba.perf" "$mitsuba_traversal")
    awk -v n="$name" -v spp="$spp" -v hz="$rate" -v e="$error_ratio" \
        -v tr="$t_rays" -v tt="$t_total" -v tv="$t_trav" \
        -v mr="$m_rays" -v mt="$m_total" -v mv="$m_trav" 'BEGIN {
        samples = 256 * 256 * spp
        # twinpath may spend 0.5 / e of Mitsuba process per sample; its non-traversal time
        # (tt - tv) stays; what is left must hold its rays at Embree rate times x.
        budget = 0.5 / e * mt - (tt - tv)
        embree_rate = mr * samples / mv
        floor = (budget > 0) ? (tr * samples / budget) / embree_rate : -1
        printf "%-14s %-9s %9.3f %11.2f %11.2f %8.1f%% %11.2f\n", n, "twinpath", tr, tt / hz,
            tv / hz, 100 * tv / tt, tr * samples / (tv / hz) / 1e6
        printf "%-14s %-9s %9.3f %11.2f %11.2f %8.1f%% %11.2f %9s\n", n, "mitsuba", mr, mt / hz,
            mv / hz, 100 * mv / mt, mr * samples / (mv / hz) / 1e6,
            (floor > 0) ? sprintf("%.2f", floor) : "none"
    }' | tee -a "$out/floor.txt"
done
