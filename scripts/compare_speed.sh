#!/usr/bin/env bash
# Speed of two twinpath binaries on one scene, measured in alternating rounds on one machine
# (a shared machine's load drifts; alternating puts both under the same drift), and their
# instruction counts under cachegrind (noise-free, one thread, few samples):
#   scripts/compare_speed.sh OLD_BINARY NEW_BINARY [SCENE] [ROUNDS]
# Prints each round's M samples/s for the CPU (256 spp) and the GPU backend (8 spp), the
# medians and the ratio new/old, then both instruction counts. Run from the repository root.
set -euo pipefail
old=$1
new=$2
scene=${3:-scenes/cornell.toml}
rounds=${4:-6}
out=$(mktemp -d)
rate() { sed -n 's/.*render [0-9.]* s, \([0-9.]*\) M samples\/s.*/\1/p'; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
for backend in "cpu --spp 256" "gpu --spp 8"; do
  : > "$out/old" ; : > "$out/new"
  for r in $(seq "$rounds"); do
    for which in old new; do
      bin=$old
      [ "$which" = new ] && bin=$new
      # shellcheck disable=SC2086
      "$bin" render "$scene" --backend $backend -o "$out/$which.exr" 2>&1 | rate >> "$out/$which"
    done
    echo "round $r, $backend: old $(tail -1 "$out/old"), new $(tail -1 "$out/new")"
  done
  o=$(median < "$out/old"); n=$(median < "$out/new")
  echo "median, $backend: old $o, new $n M samples/s, ratio $(awk -v a="$n" -v b="$o" 'BEGIN {printf "%.3f", a / b}')"
done
for which in old new; do
  bin=$old
  [ "$which" = new ] && bin=$new
  valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file="$out/cg.$which" \
    "$bin" render "$scene" --backend cpu --spp 4 --threads 1 -o "$out/cg_$which.exr" >/dev/null 2>&1
  echo "instructions, $which: $(sed -n 's/^summary: //p' "$out/cg.$which")"
done
if cmp -s "$out/cg_old.exr" "$out/cg_new.exr"; then echo "images: byte-identical"; else echo "images: DIFFER"; fi
rm -rf "$out"
