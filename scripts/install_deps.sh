#!/usr/bin/env bash
# Installs the build and runtime dependencies of JVLDLoc on Debian 12 (bookworm) or newer.
# clang-14, its sanitizer/libFuzzer runtimes (libclang-rt-14-dev) and llvm-14 (llvm-symbolizer
# for readable sanitizer reports) are for the sanitizer and fuzz build of scripts/test.sh.
# Idempotent and non-interactive: packages already present are skipped.
# Usage: sudo scripts/install_deps.sh   (or as root)
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libopencv-dev libpcl-dev libceres-dev
  libcli11-dev nlohmann-json3-dev libhdf5-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev libtbb-dev
  libopencv-contrib-dev
  python3 python3-matplotlib python3-numpy
  clang-14 libclang-rt-14-dev llvm-14
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install_deps: need root to install: ${missing[*]}" >&2; exit 1
  fi
fi

echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install_deps: done"
