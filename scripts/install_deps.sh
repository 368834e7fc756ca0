#!/usr/bin/env bash
# Installs what the build and tests need on Debian 12 (run as root). Idempotent and quiet when
# everything is already there, so `make test` can call it every time.
set -euo pipefail

apt_packages=(cmake ninja-build g++ ccache pkg-config
              libglm-dev libembree-dev libosd-dev libopenexr-dev libimath-dev libtbb-dev libpng-dev catch2)

missing=()
for p in "${apt_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "install_deps: missing Debian packages (${missing[*]}); run as root or install them" >&2
    exit 1
  fi
  echo "install_deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
