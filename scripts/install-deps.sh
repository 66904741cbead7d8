#!/usr/bin/env bash
# Installs the Debian 12 packages Kairos needs, calling apt-get only for those that are missing.
# Safe to run repeatedly; non-interactive (works with CI=true and no terminal).
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libgmock-dev
  zlib1g-dev
  python3 python3-gsd python3-numpy python3-wheel python3-venv
  python3-dev pybind11-dev
  libopenmpi-dev openmpi-bin
)

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
if [ "$(id -u)" -ne 0 ]; then
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
