#!/usr/bin/env bash
# Installs everything twinpath needs on Debian 12 (idempotent):
#   - the pinned nightly toolchain (rustup) with rustfmt and clippy; with --kernel-from-source
#     also rust-src, rustc-dev and llvm-tools, which rust-gpu needs to compile the kernel to
#     SPIR-V (scripts/build_kernel.sh; a plain build runs the shipped module and needs neither);
#   - Vulkan loader, lavapipe (Mesa 25 from bookworm-backports, for the GPU backend without a GPU),
#     vulkan-tools, validation layers, spirv-tools (spirv-val), DejaVu fonts (bench plot text).
# Apt steps run only as root or via sudo; they are skipped when everything is already installed.
set -euo pipefail
cd "$(dirname "$0")/.."

TOOLCHAIN=$(sed -n 's/^channel *= *"\(.*\)"/\1/p' rust-toolchain.toml)
components=(rustfmt clippy)
[ "${1:-}" = --kernel-from-source ] && components+=(rust-src rustc-dev llvm-tools)
if ! rustup toolchain list | grep -q "^${TOOLCHAIN}"; then
  echo "setup: installing Rust toolchain ${TOOLCHAIN} (${components[*]})" >&2
  rustup toolchain install "${TOOLCHAIN}" --profile minimal "${components[@]/#/-c}"
else
  installed=$(rustup component list --toolchain "${TOOLCHAIN}" --installed)
  for c in "${components[@]}"; do
    if ! grep -q "^$c" <<<"$installed"; then
      echo "setup: adding $c to ${TOOLCHAIN}" >&2
      rustup component add --toolchain "${TOOLCHAIN}" "$c"
    fi
  done
fi

need_pkgs=()
# slurmctld, slurmd, slurm-client: the one-node cluster of scripts/slurm/test_cluster.sh.
for p in libvulkan1 vulkan-tools vulkan-validationlayers spirv-tools mesa-vulkan-drivers fonts-dejavu-core \
         slurmctld slurmd slurm-client; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need_pkgs+=("$p")
done
# lavapipe must come from backports (Mesa >= 25 exposes the ray-tracing extensions)
mesa_ver=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
case "$mesa_ver" in 2[5-9].*|3*) ;; *) need_mesa=1 ;; esac

if [ ${#need_pkgs[@]} -gt 0 ] || [ -n "${need_mesa:-}" ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  if [ ! -f /etc/apt/sources.list.d/backports.sources ] && ! grep -rqs bookworm-backports /etc/apt/sources.list /etc/apt/sources.list.d/; then
    echo "setup: adding bookworm-backports (derived from this machine's Debian source entry)" >&2
    if [ -f /etc/apt/sources.list.d/debian.sources ]; then
      awk -v RS= 'NR==1' /etc/apt/sources.list.d/debian.sources \
        | sed 's/^Suites:.*/Suites: bookworm-backports/' | $SUDO tee /etc/apt/sources.list.d/backports.sources >/dev/null
    else
      line=$(grep -m1 '^deb .* bookworm ' /etc/apt/sources.list)
      echo "$line" | sed 's/ bookworm / bookworm-backports /' | $SUDO tee /etc/apt/sources.list.d/backports.list >/dev/null
    fi
  fi
  echo "setup: installing Debian packages" >&2
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q -t bookworm-backports mesa-vulkan-drivers
  $SUDO apt-get install -y -q libvulkan1 vulkan-tools vulkan-validationlayers spirv-tools fonts-dejavu-core
  $SUDO apt-get install -y -q --no-install-recommends slurmctld slurmd slurm-client
fi
