#!/usr/bin/env bash
# Installs everything Monolith needs to build, test and benchmark on Debian 12 (bookworm).
# Idempotent; run as root (or with sudo available).
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PACKAGES=(
  cmake make g++ pkg-config
  libeigen3-dev libtbb-dev libfcl-dev libccd-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libbullet-dev libbox2d-dev
  python3 python3-vtk9 python3-matplotlib
  slurm-wlm munge
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
