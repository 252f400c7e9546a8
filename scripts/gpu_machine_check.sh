#!/usr/bin/env bash
# The device check of a borrowed GPU machine, from what scripts/gpu_machine_prepare.sh put into
# .gpu/: is there a Vulkan ray-tracing device; do the GPU tests pass, and the function bounds
# (issue 35); how much the ray-generation shader keeps live across its trace calls (the driver's
# stack size); how fast is a render, against the baseline binary if one was prepared, and against
# Mitsuba 3 cuda_ad_rgb at equal error (issue 36, scripts/gpu_peer_table.py reads the images back
# here). Writes $OUT/log.txt, $OUT/tests.txt (each test binary's log as it ends) and
# $OUT/peer.tar.gz (the peer images). Each step under its own limit; at most about 9 minutes;
# SKIP_TESTS=1 runs the speed and peer steps alone.
exec > >(tee "${OUT:-/tmp}/log.txt") 2>&1
set -x
R=$PWD
for f in .gpu/debs/lib*.deb .gpu/debs/spirv-tools*.deb; do dpkg -x $f /; done; ldconfig
rm -rf /tmp/vl; mkdir -p /tmp/vl && dpkg -x .gpu/debs/vulkan-validationlayers*.deb /tmp/vl
export VK_LAYER_PATH=/tmp/vl/usr/share/vulkan/explicit_layer.d
export LD_LIBRARY_PATH=/tmp/vl/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
if [ -e /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json VK_ICD_FILENAMES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
# the test binaries find scenes through the compile-time path /work/main
if [ "$R" != /work/main ]; then mkdir -p /work; rm -rf /work/main; ln -s "$R" /work/main; fi
rm -rf /tmp/gpubin && mkdir -p /tmp/gpubin && tar -C /tmp/gpubin -xJf .gpu/bin.tar.xz ||
  python3 -c "import tarfile; tarfile.open('.gpu/bin.tar.xz').extractall('/tmp/gpubin')"
B=/tmp/gpubin/bin
mkdir -p target/debug && cp $B/twinpath target/debug/twinpath
set +x
echo "== machine"; nvidia-smi -L; nproc; date -u; python3 --version
echo "== twinpath info"; timeout -k 5 60 $B/twinpath info; j=$(python3 -c "import json;print(json.load(open('$VK_DRIVER_FILES'))['ICD']['library_path'])" 2>/dev/null); echo "icd lib $j"; ldd $(ls /usr/local/nvidia/lib64/$j /usr/local/nvidia/lib/$j $j 2>/dev/null | head -1) 2>&1 | grep -i "not found"; VK_LOADER_DEBUG=error,driver timeout -k 5 30 $B/twinpath info 2>&1 | grep -iE "error|fail|driver" | head -20
if timeout -k 5 60 $B/twinpath info | grep -q "gpu backend: unavailable"; then echo "NO VULKAN DEVICE"; exit 3; fi
# Correctness first, every part at once (16 cores; the speed step runs alone afterwards): the
# function bounds; the module, the backends' equivalence and the furnace; every other test with
# a GPU part, whole binaries (their CPU parts too) in four queues, one Vulkan context each
# (specialize_adaptive alone in one: it compiles two pipelines per scene, 2 to 10 s each on
# the H200), --test-threads=1 within each because of the two-thread hang, each binary under its
# own limit and none started after the step's QEND s, so that nothing outlives the step; and the
# two-thread hang itself, sobol's two GPU tests in two threads of one process, with the
# validation layers and without (TWINPATH_TESTS_NO_VALIDATION), a stuck fence saying so every
# minute. Each log ends with its exit status and time. tests/tests/gpu_machine_check.rs fails
# when a test file with a GPU part is missing from the queues or from the prepared binaries.
if [ -z "${SKIP_TESTS:-}" ]; then
echo "== tests (issue 35)"
rm -rf /tmp/tl && mkdir -p /tmp/tl
T=${OUT:-/tmp}/tests.txt
# run NAME LIMIT CMD...: CMD under LIMIT s (then SIGKILL 5 s later), its log appended to $T the
# moment it ends (a run killed at its limit still returns what finished).
run() { local n=$1 l=$2 s=$(date +%s); shift 2; timeout -k 5 $l "$@" > /tmp/tl/$n.log 2>&1; printf '\nrc %s in %s s (124: timed out)\n' $? $(( $(date +%s) - s )) >> /tmp/tl/$n.log
  { echo "-- $n"; grep -vE "^test .* ok$|^$" /tmp/tl/$n.log | tail -${TAIL:-60}; } >> $T; }
end=$(( $(date +%s) + ${QEND:-200} ))
queue() { for t in "$@"; do [ $(date +%s) -ge $end ] && { echo "-- $t: not run, the step's time is up" >> $T; continue; }; run $t ${QT:-150} $B/$t --test-threads=1; done; }
run gpu_functions 150 $B/gpu_functions --test-threads=1 --nocapture &
(queue spirv_module gpu_render cycles; TWINPATH_FURNACE_GPU_SPP=24576 run furnace 90 $B/furnace gpu --nocapture) &
QT=235 queue specialize_adaptive &
queue gltf sobol media_grids normal_maps camera vertex_colours split &
queue instances large_floor device_limits opacity light_selection textures reflecting_lights &
queue media punctual_lights closed_form_materials hard_lighting scene_scale triangle_lights environment texture_sets shading_normals &
(run hang_validation 75 $B/sobol gpu both_backends --test-threads=2
 TWINPATH_TESTS_NO_VALIDATION=1 run hang_no_validation 75 $B/sobol gpu both_backends --test-threads=2) &
# Not `wait`: on 2026-12-04 something in this step outlived every limit above (SIGTERM) and the
# step never ended. Past the step's end, what still runs is shown (state, kernel wait channel)
# and killed, and the speed step goes on.
stop=$(( $(date +%s) + ${STEP_END:-330} ))
while [ -n "$(jobs -rp)" ] && [ $(date +%s) -lt $stop ]; do sleep 5; done
if [ -n "$(jobs -rp)" ]; then echo "-- still running at the step's end" >> $T; ps -eo pid,etime,stat,wchan:32,args | grep "$B/" | grep -v grep >> $T; kill -9 $(jobs -p); pkill -9 -f "$B/"; fi
cat $T
fi
echo "== live state across trace calls (issue 36)"
# The ray-generation group's stack size as this device's driver compiles it (what the shader
# keeps live across traceRayEXT; RADV's numbers in docs/gpu.md), the current module against the
# earlier ones gpu_machine_prepare.sh put in .gpu/modules.
for sc in cornell materials gltf_showcase; do for m in current .gpu/modules/*.spv; do
  [ $m = current ] && m=
  echo "-- $sc ${m:-current}: $(timeout -k 5 60 $B/pipeline_stats scenes/$sc.toml $m 2>&1 | tail -1)"
done; done
echo "== speed (issue 36)"
python3 scripts/torus_scenes.py /tmp/gs 4000 1000000
G=${GPU_SPP:-2048}
gpu() { echo "-- $1 $2"; timeout -k 5 30 $B/$1 render $2 --backend gpu --spp $G -o /tmp/x.exr 2>&1 | grep -E "backend|rror"; }
# The 2026-11-30 binary (gpu_machine_prepare.sh's BASELINE) on its own scenes, alternating with
# the current one: the same machine, minutes apart (docs/gpu.md: half the speed on 2026-12-04).
if [ -e $B/twinpath_baseline ]; then
  echo "baseline $(cat .gpu/baseline_commit)"
  for s in cornell meshes; do for bin in twinpath_baseline twinpath twinpath_baseline twinpath; do
    sc=.gpu/baseline_scenes/$s.toml; [ $bin = twinpath ] && sc=scenes/$s.toml; gpu $bin $sc; done; done
  for bin in twinpath_baseline twinpath; do gpu $bin /tmp/gs/mesh_4000.toml; done
fi
for sc in scenes/materials.toml /tmp/gs/mesh_1000000.toml scenes/gltf_showcase.toml; do gpu twinpath $sc; done
# Splitting at the first vertex (docs/performance.md): what a split sample costs on this GPU
# (two continuations halve Cornell's error; on the CPU's packets they cost 1.95x).
for v in off 2 off 2; do gpu twinpath "scenes/cornell.toml --set split=$v"; done
# Against Mitsuba 3 cuda_ad_rgb (gpu_machine_prepare.sh's bundle): both render the scenes of
# scripts/gpu_peer_scenes.txt at the same sample count; scripts/gpu_peer_table.py measures the
# images' error here (from $OUT/peer.tar.gz: a run returns at most 8 files).
rm -rf /tmp/peer && mkdir -p /tmp/peer
for s in $(awk '{ sub(/#.*/, "") } NF { print $1 }' scripts/gpu_peer_scenes.txt); do
  timeout -k 5 40 $B/twinpath render scenes/$s.toml --backend gpu --spp ${PEER_SPP:-1024} -o /tmp/peer/twinpath_$s.exr > /tmp/peer/twinpath_$s.txt 2>&1; grep -E "backend|rror" /tmp/peer/twinpath_$s.txt
done
if [ -e .gpu/mitsuba.tar.xz ]; then
  echo "== Mitsuba cuda_ad_rgb"
  rm -rf /tmp/mb && mkdir -p /tmp/mb && { tar -C /tmp/mb -xJf .gpu/mitsuba.tar.xz ||
    python3 -c "import tarfile; tarfile.open('.gpu/mitsuba.tar.xz').extractall('/tmp/mb')"; }
  py=$(python3 -c 'import sys; print(f"{sys.version_info[0]}{sys.version_info[1]}")')
  lib() { for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /usr/lib64; do ls $d/$1* 2>/dev/null; done | head -1; }
  export DRJIT_LIBCUDA_PATH=$(lib libcuda.so) DRJIT_LIBOPTIX_PATH=$(lib libnvoptix.so)
  echo "python $py, libcuda $DRJIT_LIBCUDA_PATH, optix $DRJIT_LIBOPTIX_PATH"
  (cd scripts && PYTHONPATH=/tmp/mb/py$py timeout -k 5 150 python3 peer_mitsuba_gpu.py /tmp/peer --spp ${PEER_SPP:-1024} 2>&1 | tail -20)
fi
tar -C /tmp -czf ${OUT:-/tmp}/peer.tar.gz peer
timeout -k 5 30 $B/twinpath render scenes/cornell.toml --backend gpu --spp 1024 --validation -o /tmp/v.exr 2>&1 | tail -3
echo "== done"; date -u
