#!/usr/bin/env bash
# The device check of a borrowed GPU machine, from what scripts/gpu_machine_prepare.sh put into
# .gpu/: is there a Vulkan ray-tracing device, how fast is a render against the CPU backend
# (Cornell, meshes.toml, materials.toml, tori of 4k to 1M triangles), do the GPU tests pass. Writes
# $OUT/log.txt. About 3 minutes on an H200.
exec > >(tee "${OUT:-/tmp}/log.txt") 2>&1
set -x
R=$PWD
for f in .gpu/debs/lib*.deb; do dpkg -x $f /; done; ldconfig
rm -rf /tmp/vl; mkdir -p /tmp/vl && dpkg -x .gpu/debs/vulkan-validationlayers*.deb /tmp/vl
export VK_LAYER_PATH=/tmp/vl/usr/share/vulkan/explicit_layer.d
export LD_LIBRARY_PATH=/tmp/vl/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
if [ -e /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json VK_ICD_FILENAMES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
# the test binaries find scenes through the compile-time path /work/main
if [ "$R" != /work/main ]; then mkdir -p /work; rm -rf /work/main; ln -s "$R" /work/main; fi
mkdir -p target/debug && cp .gpu/bin/twinpath target/debug/twinpath
B=$R/.gpu/bin
set +x
echo "== machine"; nvidia-smi -L; nproc; date -u
echo "== twinpath info"; timeout 60 $B/twinpath info; j=$(python3 -c "import json;print(json.load(open('$VK_DRIVER_FILES'))['ICD']['library_path'])" 2>/dev/null); echo "icd lib $j"; ldd $(ls /usr/local/nvidia/lib64/$j /usr/local/nvidia/lib/$j $j 2>/dev/null | head -1) 2>&1 | grep -i "not found"; VK_LOADER_DEBUG=error,driver timeout 30 $B/twinpath info 2>&1 | grep -iE "error|fail|driver" | head -20
if timeout 60 $B/twinpath info | grep -q "gpu backend: unavailable"; then echo "NO VULKAN DEVICE"; exit 3; fi
echo "== speed"
python3 scripts/torus_scenes.py /tmp/gs 4000 16000 65000 262000 1000000
sp() { echo "-- $1"; for b in gpu gpu cpu; do n=${GPU_SPP:-4096}; [ $b = cpu ] && n=${CPU_SPP:-256}; timeout 25 $B/twinpath render $1 --backend $b --spp $n -o /tmp/x.exr 2>&1 | grep -E "backend|rror"; done; }
sp scenes/cornell.toml; sp scenes/meshes.toml; sp scenes/materials.toml
timeout 30 $B/twinpath render scenes/cornell.toml --backend gpu --spp 1024 -o ${OUT:-/tmp}/cornell_gpu.png 2>&1 | grep -E "backend|rror"
timeout 30 $B/twinpath render scenes/cornell.toml --backend gpu --spp 1024 --validation -o /tmp/v.exr 2>&1 | tail -5
echo "== tests"
for t in spirv_module gpu_functions gpu_render; do echo "-- $t"; timeout ${TT:-120} $B/$t --test-threads=1 2>&1 | grep -vE "^test .* ok$|^$"; done
echo "-- closed_form_materials"; timeout 120 $B/closed_form_materials --test-threads=1 2>&1 | grep -vE "^test .* ok$|^$"
# Holes through the any-hit shaders, and the second texture coordinates, on a real GPU.
for t in opacity texture_sets; do echo "-- $t"; timeout 120 $B/$t --test-threads=1 --nocapture 2>&1 | grep -vE "^test .* ok$|^$"; done
for t in scene_scale specialize_adaptive hard_lighting light_selection sobol; do echo "-- $t gpu"; timeout 60 $B/$t gpu both_backends --test-threads=1 2>&1 | grep -vE "^test .* ok$|^$"; done
# The two-thread hang (docs/gpu.md): sobol's two GPU tests in two threads of one process,
# with a short limit; a stuck fence now says so every minute with the process's context count.
echo "-- sobol gpu, two threads (the hang)"; timeout 150 $B/sobol gpu both_backends --test-threads=2 2>&1 | grep -vE "^test .* ok$|^$"; echo "rc ${PIPESTATUS[0]} (124: timed out)"
echo "-- furnace gpu, 10^8 samples"; TWINPATH_FURNACE_GPU_SPP=24576 timeout 90 $B/furnace gpu --nocapture 2>&1 | tail -15
echo "== mesh scaling"
for n in 4000 16000 65000 262000 1000000; do sp /tmp/gs/mesh_$n.toml; done
echo "== done"; date -u
