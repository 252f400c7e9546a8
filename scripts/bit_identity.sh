#!/usr/bin/env bash
# Renders scenes in five configurations with two twinpath binaries and compares the EXRs byte
# for byte: the check that a change leaves scenes without its feature exactly as they were
# (docs/design.md, "Skip what a scene doesn't need"), or that a refactoring changed no image.
#   scripts/bit_identity.sh OLD_BINARY NEW_BINARY [OUT_DIR [SCENE...]]
# SCENE is a name in scenes/ without .toml; the default is every scene there.
# Run from the repository root; the GPU configuration needs a Vulkan ray-tracing device
# (lavapipe here).
set -euo pipefail
old=$1
new=$2
out=${3:-target/bit_identity}
shift $(( $# < 3 ? $# : 3 ))
mkdir -p "$out"
if [ $# -gt 0 ]; then
  scenes=("$@")
else
  scenes=()
  for f in scenes/*.toml; do scenes+=("$(basename "$f" .toml)"); done
fi
configs=(
  "cpu16:--backend cpu --spp 16"
  "onepath:--backend cpu --spp 16 --set packets=false"
  "adaptive:--backend cpu --spp 32 --set adaptive_target=0.05"
  "constant_rr:--backend cpu --spp 16 --roulette constant"
  "gpu4:--backend gpu --spp 4"
)
differ=0
for scene in "${scenes[@]}"; do
  for config in "${configs[@]}"; do
    name=${config%%:*}
    args=${config#*:}
    for which in old new; do
      bin=$old
      [ "$which" = new ] && bin=$new
      # shellcheck disable=SC2086
      "$bin" render "scenes/$scene.toml" $args -o "$out/${scene}_${name}_$which.exr" >/dev/null 2>&1
    done
    if cmp -s "$out/${scene}_${name}_old.exr" "$out/${scene}_${name}_new.exr"; then
      echo "identical  $scene $name"
    else
      echo "DIFFERENT  $scene $name"
      differ=1
    fi
  done
done
exit $differ
