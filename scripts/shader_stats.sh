#!/usr/bin/env bash
# The ray-generation shader's cost as a GPU compiler sees it, offline: Mesa's RADV on null
# hardware (no GPU; the driver is in mesa-vulkan-drivers with lavapipe) compiles the pipeline a
# render of SCENE uses (cargo run --example pipeline_stats) and prints its statistics. One row
# per revision, from that revision's shipped module (kernel/shipped/kernel.spv) with the current
# host: registers (VGPRs), instructions, waves per SIMD (occupancy), RADV's estimate of the
# cycles per wave (inverse throughput) and scratch (spills), as RADV compiles for a render (all
# stages inlined into one shader); then, compiled with the stages apart (pipeline_stats
# --separate, as GPUs with hardware traversal do), the ray-tracing stack the ray-generation
# shader needs (what it keeps live across a trace call), its registers and scratch. lavapipe
# runs the kernel as LLVM code for the CPU and cannot show what a GPU pays for registers; on
# the H200 the speed of Cornell fell 2.5x between 8bc5ec3 and f224601 while lavapipe's did not
# move (docs/gpu.md).
# RADV's cycle estimate weighs the code after a conditional return as less likely to run: a
# never-taken `if count == 0 { return }` halves it (docs/gpu.md), so compare it only between
# modules of the same control flow; registers, waves, scratch and the stack are counts.
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
printf '%-12s %6s %8s %6s %12s %8s | %6s %6s %8s\n' revision vgprs instrs waves cycles/wave scratch stack vgprs scratch
for rev in "${@:-kernel/shipped/kernel.spv}"; do
  if [ -f "$rev" ]; then spv=$rev; else spv=$tmp/module.spv; git show "$rev:kernel/shipped/kernel.spv" > "$spv"; fi
  for compilation in "" --separate; do
    MESA_SHADER_CACHE_DISABLE=true RADV_DEBUG=shaderstats RADV_FORCE_FAMILY=navi31 VK_DRIVER_FILES=$icd \
      target/debug/examples/pipeline_stats "$scene" "$spv" $compilation > "$tmp/log${compilation}" 2>&1 || true
  done
  # A run that printed no statistics shows its error instead.
  awk -v r="$rev" 'FNR == 1 {f++; g = 0}
      /Ray Generation/{g=1} g&&/^VGPRs/{v[f]=$2} g&&/^Instructions/{i[f]=$2}
      g&&/Subgroups per SIMD/{w[f]=$4} g&&/Inverse Throughput/{t[f]=$3; g=0} g&&/^Scratch size/{s[f]=$3}
      /raygen stack/{st[f]=$(NF-1)} /^Error/ && e == "" {e=$0}
      END{if (v[1] == "" || v[2] == "") printf "%-12s no statistics: %s\n", r, e
          else printf "%-12s %6s %8s %6s %12s %8s | %6s %6s %8s\n", r, v[1], i[1], w[1], t[1], s[1], st[2], v[2], s[2]}' \
      "$tmp/log" "$tmp/log--separate"
done
