#!/usr/bin/env bash
# Installs the Debian packages contactlink builds and runs with, only when
# some are missing. Safe to run again: it does nothing when all are present.
# `--peers` adds what `make bench-peers` runs beside contactlink (Gmsh and
# CalculiX); neither is needed to build or test.
set -euo pipefail
packages=(
  petsc-dev libopenmpi-dev openmpi-bin libmetis-dev libhdf5-openmpi-dev
  libclang-dev clang pkg-config hdf5-tools libopenblas0-serial
  python3-matplotlib python3-h5py fonts-dejavu-core
  calculix-ccx-test
)
if [ "${1:-}" = "--peers" ]; then
  packages+=(gmsh calculix-ccx)
fi
missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
