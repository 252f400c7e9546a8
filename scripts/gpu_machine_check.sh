#!/usr/bin/env bash
# The device check of a borrowed GPU machine, from what scripts/gpu_machine_prepare.sh put into
# .gpu/: is there a Vulkan ray-tracing device, how fast is a render against the CPU backend
# (Cornell, meshes.toml, materials.toml, tori of 4k to 1M triangles), do the GPU tests pass. Writes
# $OUT/log.txt. Ordered by what matters most, each step under its own limit; at most about 9 minutes.
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
echo "== machine"; nvidia-smi -L; nproc; date -u; python3 --version; ldconfig -p | grep -E "libcuda.so|libnvrtc" | head -3  # for a later Mitsuba cuda_ad_rgb peer (issue 36): its wheel is per Python version
echo "== twinpath info"; timeout 60 $B/twinpath info; j=$(python3 -c "import json;print(json.load(open('$VK_DRIVER_FILES'))['ICD']['library_path'])" 2>/dev/null); echo "icd lib $j"; ldd $(ls /usr/local/nvidia/lib64/$j /usr/local/nvidia/lib/$j $j 2>/dev/null | head -1) 2>&1 | grep -i "not found"; VK_LOADER_DEBUG=error,driver timeout 30 $B/twinpath info 2>&1 | grep -iE "error|fail|driver" | head -20
if timeout 60 $B/twinpath info | grep -q "gpu backend: unavailable"; then echo "NO VULKAN DEVICE"; exit 3; fi
echo "== function bounds (issue 35)"
timeout 120 $B/gpu_functions --test-threads=1 --nocapture 2>&1 | grep -vE "^test .* ok$|^$"
echo "== tests"
for t in spirv_module gpu_render; do echo "-- $t"; timeout ${TT:-120} $B/$t --test-threads=1 2>&1 | grep -vE "^test .* ok$|^$"; done
echo "-- furnace gpu, 10^8 samples"; TWINPATH_FURNACE_GPU_SPP=24576 timeout 90 $B/furnace gpu --nocapture 2>&1 | tail -15
# Every other test with a GPU part, whole binaries (their CPU parts too), in four queues run
# side by side (one Vulkan context each; specialize_adaptive alone in one, it compiles two
# pipelines per scene), --test-threads=1 within each because of the two-thread
# hang; each binary under its own limit and none started after the step's 200 s, so that
# nothing outlives the step; the slowest first (the H200 compiled a pipeline in 2 to 10 s on
# 2026-12-04). Each log ends with its exit status and time.
echo "== the other GPU tests"
mkdir -p /tmp/tl
end=$(( $(date +%s) + ${QEND:-200} ))
queue() { for t in "$@"; do s=$(date +%s); [ $s -ge $end ] && { echo "not run: the step's time is up" > /tmp/tl/$t.log; continue; }; timeout ${QT:-150} $B/$t --test-threads=1 > /tmp/tl/$t.log 2>&1; echo "rc $? in $(( $(date +%s) - s )) s" >> /tmp/tl/$t.log; done; }
QT=235 queue specialize_adaptive &
queue gltf sobol media_grids normal_maps camera vertex_colours &
queue instances opacity light_selection textures reflecting_lights &
queue media punctual_lights closed_form_materials hard_lighting scene_scale triangle_lights environment texture_sets shading_normals &
wait
for f in /tmp/tl/*.log; do echo "-- $(basename $f .log)"; grep -vE "^test .* ok$|^$" $f | tail -25; done
echo "== speed"
python3 scripts/torus_scenes.py /tmp/gs 4000 16000 65000 262000 1000000
sp() { echo "-- $1"; for b in gpu gpu cpu; do n=${GPU_SPP:-4096}; [ $b = cpu ] && n=${CPU_SPP:-256}; timeout 25 $B/twinpath render $1 --backend $b --spp $n -o /tmp/x.exr 2>&1 | grep -E "backend|rror"; done; }
sp scenes/cornell.toml; sp scenes/meshes.toml; sp scenes/materials.toml
# The scenes with media, coloured glass, textures and many lights: one GPU run and one CPU run each.
sq() { echo "-- $1"; for b in gpu cpu; do n=1024; [ $b = cpu ] && n=64; timeout 20 $B/twinpath render $1 --backend $b --spp $n -o /tmp/x.exr 2>&1 | grep -E "backend|rror"; done; }
for s in cornell_fog cornell_smoke coloured_glass gltf_showcase sky_meshes many_lights; do sq scenes/$s.toml; done
timeout 30 $B/twinpath render scenes/cornell.toml --backend gpu --spp 1024 -o ${OUT:-/tmp}/cornell_gpu.png 2>&1 | grep -E "backend|rror"
timeout 30 $B/twinpath render scenes/cornell.toml --backend gpu --spp 1024 --validation -o /tmp/v.exr 2>&1 | tail -5
for n in 4000 1000000; do sp /tmp/gs/mesh_$n.toml; done
# A baseline binary (gpu_machine_prepare.sh's BASELINE), on its own scenes, alternating with the
# current one: the same machine, minutes apart.
if [ -e $B/twinpath_baseline ]; then
  echo "== baseline $(cat .gpu/baseline_commit) against the current binary"
  for s in cornell meshes; do for bin in twinpath_baseline twinpath twinpath_baseline twinpath; do
    sc=.gpu/baseline_scenes/$s.toml; [ $bin = twinpath ] && sc=scenes/$s.toml
    echo "-- $bin $s"; timeout 25 $B/$bin render $sc --backend gpu --spp ${GPU_SPP:-4096} -o /tmp/x.exr 2>&1 | grep -E "backend|rror"
  done; done
  for bin in twinpath_baseline twinpath; do echo "-- $bin torus 4k"; timeout 25 $B/$bin render /tmp/gs/mesh_4000.toml --backend gpu --spp ${GPU_SPP:-4096} -o /tmp/x.exr 2>&1 | grep -E "backend|rror"; done
fi
# The two-thread hang (docs/gpu.md): sobol's two GPU tests in two threads of one process,
# with a short limit; a stuck fence says so every minute with the process's context count.
echo "-- sobol gpu, two threads (the hang)"; timeout 75 $B/sobol gpu both_backends --test-threads=2 2>&1 | grep -vE "^test .* ok$|^$"; echo "rc ${PIPESTATUS[0]} (124: timed out)"
echo "== done"; date -u
