#!/usr/bin/env bash
# The ray-generation shader's cost as a GPU compiler sees it, offline: Mesa's RADV on null
# hardware (no GPU; the driver is in mesa-vulkan-drivers with lavapipe) compiles the pipeline a
# render of SCENE uses (cargo run --example pipeline_stats) and prints its statistics. One row
# per revision, from that revision's shipped module (kernel/shipped/kernel.spv) with the current
# host: registers (VGPRs), instructions, waves per SIMD (occupancy), RADV's estimate of the
# cycles per wave (inverse throughput) and scratch (spills). lavapipe runs the kernel as LLVM
# code for the CPU and cannot show what a GPU pays for registers; on the H200 the speed of
# Cornell fell 2.5x between 8bc5ec3 and f224601 while lavapipe's did not move (docs/gpu.md).
# Usage: scripts/shader_stats.sh [SCENE] [REV|MODULE.spv ...]   (default: the working tree's module)
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/cornell.toml}
shift || true
cargo build -q -p twinpath --example pipeline_stats
icd=/usr/share/vulkan/icd.d/radeon_icd.json
[ -e $icd ] || { echo "RADV is not installed (mesa-vulkan-drivers)"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '%-12s %6s %8s %8s %12s %8s\n' revision vgprs instrs waves cycles/wave scratch
for rev in "${@:-kernel/shipped/kernel.spv}"; do
  if [ -f "$rev" ]; then spv=$rev; else spv=$tmp/module.spv; git show "$rev:kernel/shipped/kernel.spv" > "$spv"; fi
  # The example ends with an error on null hardware, after the statistics (see its doc); a run
  # that printed none shows its error instead.
  MESA_SHADER_CACHE_DISABLE=true RADV_DEBUG=shaderstats RADV_FORCE_FAMILY=navi31 VK_DRIVER_FILES=$icd \
    target/debug/examples/pipeline_stats "$scene" "$spv" > "$tmp/log" 2>&1 || true
  awk -v r="$rev" '/Ray Generation/{g=1} g&&/^VGPRs/{v=$2} g&&/^Instructions/{i=$2}
      g&&/Subgroups per SIMD/{w=$4} g&&/Inverse Throughput/{t=$3} g&&/^Scratch size/{s=$3}
      /^Error/ && e == "" {e=$0}
      END{if (v == "") printf "%-12s no statistics: %s\n", r, e
          else printf "%-12s %6s %8s %8s %12s %8s\n", r, v, i, w, t, s}' "$tmp/log"
done
