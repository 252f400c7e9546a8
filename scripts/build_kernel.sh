#!/usr/bin/env bash
# Compiles kernel/ to SPIR-V with rust-gpu and writes the shipped modules and their manifest:
# kernel/shipped/kernel.spv (the renderer's), kernel/shipped/probe.spv (the kernel with its feature
# `probe`: the equivalence tests' compute probes) and kernel/shipped/manifest.toml (what they were
# compiled from: every kernel source's hash, the locked packages, the toolchain, the builder's
# options).
# Run it after changing the kernel: every build checks the manifest against the sources and
# fails, naming this script, until the module is regenerated.
#
#   scripts/build_kernel.sh           regenerate both files
#   scripts/build_kernel.sh --check   compile and compare instead: exit 1 unless the shipped files
#                                     are byte for byte what the sources compile to (CI runs it)
#
# The first run installs rust-gpu's toolchain components (rust-src, rustc-dev, llvm-tools) and
# builds its compiler backend, rustc_codegen_spirv: about 12 minutes on two cores; later runs
# take seconds. RUSTGPU_* variables, which would change the module, are ignored.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-write}
case "$mode" in write|--check) ;; *) echo "usage: scripts/build_kernel.sh [--check]" >&2; exit 2 ;; esac
bash scripts/setup.sh --kernel-from-source
unset RUSTGPU_RUSTFLAGS RUSTGPU_CODEGEN_ARGS RUSTGPU_CARGOFLAGS
# The build script's OUT_DIR holds the compiled module and the manifest it would ship with. Only
# the host's build script is needed (a check of its library runs it): neither the host's code
# nor the tests are compiled, and a host that does not compile yet does not stop a kernel edit.
status=0
check=(cargo check -p twinpath --lib --features twinpath/kernel-from-source)
messages=$("${check[@]}" --message-format=json) || status=$?
# On failure, the same check again (its work is cached) prints the diagnostics readably.
[ "$status" -eq 0 ] || "${check[@]}" >&2 || true
out_dir=$(printf '%s\n' "$messages" | grep '"reason":"build-script-executed"' | grep '/host#twinpath@' \
  | sed -n 's/.*"out_dir":"\([^"]*\)".*/\1/p' | tail -n 1)
if [ -z "$out_dir" ] || [ ! -f "$out_dir/kernel.spv" ] || [ ! -f "$out_dir/probe.spv" ] \
   || [ ! -f "$out_dir/manifest.toml" ]; then
  echo "build_kernel: cargo reported no build-script output with kernel.spv, probe.spv and manifest.toml" >&2
  exit 1
fi
[ "$status" -eq 0 ] || echo "build_kernel: the module was compiled, but the host's library did not check (cargo exit $status)" >&2
if [ "$mode" = --check ]; then
  status=0
  for f in kernel.spv probe.spv manifest.toml; do
    if cmp -s "$out_dir/$f" "kernel/shipped/$f"; then
      echo "build_kernel: kernel/shipped/$f is byte for byte what the sources compile to" >&2
    else
      echo "build_kernel: kernel/shipped/$f DIFFERS from what the sources compile to ($out_dir/$f)" >&2
      status=1
    fi
  done
  [ "$status" -eq 0 ] || diff "$out_dir/manifest.toml" kernel/shipped/manifest.toml >&2 || true
  exit "$status"
fi
mkdir -p kernel/shipped
cp "$out_dir/kernel.spv" "$out_dir/probe.spv" "$out_dir/manifest.toml" kernel/shipped/
echo "build_kernel: wrote kernel/shipped/kernel.spv ($(wc -c < kernel/shipped/kernel.spv) bytes)," \
  "probe.spv ($(wc -c < kernel/shipped/probe.spv) bytes) and their manifest" >&2
