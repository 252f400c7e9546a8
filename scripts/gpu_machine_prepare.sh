#!/usr/bin/env bash
# Prepares a run of scripts/gpu_machine_check.sh on a borrowed Linux x86-64 machine with a GPU
# and no network (docs/gpu.md, "An NVIDIA H200"): builds here, then puts into .gpu/ (ignored
# by git) what that machine lacks: the Debian packages of the Vulkan loader, libglvnd
# (NVIDIA's Vulkan driver is libGLX_nvidia.so.0, which needs it), the validation layers and
# spirv-val (spirv_module.rs runs it); the stripped twinpath binary and the GPU test binaries
# (one xz archive); Mitsuba 3's files for its GPU variant (another). Run there:
# `bash scripts/gpu_machine_check.sh`.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --workspace --all-targets
rm -rf .gpu && mkdir -p .gpu/bin .gpu/debs /tmp/twinpath-apt/partial
apt_opts=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/twinpath-apt)
apt-get "${apt_opts[@]}" update -qq
(cd .gpu/debs && apt-get "${apt_opts[@]}" download libvulkan1 libglvnd0 libglx0 libegl1 libgl1 \
  libopengl0 libgles2 vulkan-validationlayers spirv-tools)
strip -o .gpu/bin/twinpath target/debug/twinpath
strip -o .gpu/bin/pipeline_stats target/debug/examples/pipeline_stats
# Earlier shipped modules whose ray-generation stack the check asks the device for beside the
# current one (STATS_REVS; default 5de8811, the module before the live-state change).
mkdir -p .gpu/modules
for rev in ${STATS_REVS:-5de8811}; do git show "$rev:kernel/shipped/kernel.spv" > ".gpu/modules/$rev.spv"; done
for t in gpu_functions gpu_render spirv_module furnace scene_scale specialize_adaptive \
  hard_lighting light_selection sobol closed_form_materials opacity texture_sets media media_grids \
  triangle_lights environment textures normal_maps gltf instances punctual_lights \
  reflecting_lights vertex_colours shading_normals camera split large_floor device_limits \
  cycles; do
  f=$(cargo test -p twinpath-tests --test "$t" --no-run 2>&1 | sed -n 's/.*Executable .*(\(.*\))/\1/p')
  strip -o ".gpu/bin/$t" "$f"
done
# With BASELINE=<commit>: that commit's twinpath and scenes as well (built in a worktree), which
# the check times beside the current binary, so that a change in speed between two runs on a
# lent machine can be told from the machine's (docs/gpu.md, "The H200 again").
# A worktree already at that commit (BASELINE_DIR) is reused with its build.
if [ -n "${BASELINE:-}" ]; then
  w=${BASELINE_DIR:-/tmp/twinpath-baseline}
  if [ "$(git -C "$w" rev-parse HEAD 2>/dev/null)" != "$(git rev-parse "$BASELINE^{commit}")" ]; then
    git worktree remove --force "$w" 2>/dev/null || rm -rf "$w"
    git worktree prune
    git worktree add --detach "$w" "$BASELINE"
  fi
  (cd "$w" && CARGO_TARGET_DIR="$w/target" cargo build -p twinpath)
  strip -o .gpu/bin/twinpath_baseline "$w/target/debug/twinpath"
  cp -r "$w/scenes" .gpu/baseline_scenes
  git -C "$w" rev-parse HEAD > .gpu/baseline_commit
fi
# Mitsuba 3 cuda_ad_rgb, the GPU peer (issue 36; MITSUBA=0 leaves it out): its files for the lent
# machine's CPython (3.12 on the H200 image; MITSUBA_PYTHON="3.12 3.13" for several), cut to
# what scripts/peer_mitsuba_gpu.py renders (scripts/mitsuba_gpu_bundle.py): 17 MB.
if [ "${MITSUBA:-1}" != 0 ]; then
  wheels=target/mitsuba-wheels versions=()
  for v in ${MITSUBA_PYTHON:-3.12}; do
    pip download -q --no-deps --only-binary=:all: --python-version $v \
      --platform manylinux_2_28_x86_64 -d $wheels mitsuba==3.9.1 drjit==1.5.0
    versions+=("${v/./}")
  done
  pip download -q --no-deps -d $wheels typing_extensions
  python3 scripts/mitsuba_gpu_bundle.py $wheels /tmp/twinpath-mitsuba "${versions[@]}"
  tar -C /tmp/twinpath-mitsuba -cf - . | xz -9 -T0 > .gpu/mitsuba.tar.xz
fi
# The binaries share most of their code: one xz stream over all of them is 14 MB instead of
# 225 MB, which keeps .gpu within what a lent machine's working tree may carry (64 MiB).
tar -C .gpu -cf - bin | xz -9 > .gpu/bin.tar.xz
rm -rf .gpu/bin
du -sh .gpu
