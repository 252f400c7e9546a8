#!/usr/bin/env bash
# Fuzzes the scene parser, the PLY and OBJ loaders and the glTF loader with libFuzzer (cargo-fuzz), each for
# SECONDS (first argument, default 60), from the seed corpora in fuzz/corpus (copied, so new
# inputs the fuzzer finds do not land in the repository), with a 2 GiB memory limit and a 10 s
# limit per input: a panic, a crash, a hang or unbounded memory fails the run, and libFuzzer
# saves the input under fuzz/artifacts/ to turn into a regression test. The seed is fixed
# (FUZZ_SEED, default 1) so that a run here explores the same inputs, in the same order, as a run
# in CI; FUZZ_SEED=0 lets libFuzzer pick one (for longer exploratory runs).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
for target in scene ply obj gltf; do
  work=$(mktemp -d)
  cp fuzz/corpus/"$target"/* "$work"/
  echo "fuzz: $target for ${seconds}s" >&2
  status=0
  cargo fuzz run "$target" "$work" -- -max_total_time="$seconds" -seed="${FUZZ_SEED:-1}" -rss_limit_mb=2048 -timeout=10 \
    -print_final_stats=1 > "$work.log" 2>&1 || status=$?
  grep -E "^(Done|stat::number_of_executed_units|stat::peak_rss_mb)" "$work.log" >&2 || true
  if [ "$status" -ne 0 ]; then
    tail -60 "$work.log" >&2
    echo "fuzz: $target FAILED (exit $status)" >&2
    exit 1
  fi
  rm -rf "$work" "$work.log"
done
echo "fuzz: no crash, hang or memory blow-up in any target" >&2
