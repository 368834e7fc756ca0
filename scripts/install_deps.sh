#!/usr/bin/env bash
# Installs what the build and tests need on Debian 12 (run as root). Idempotent and quiet when
# everything is already there, so `make test` can call it every time. clang-format is for
# scripts/check_format.sh; chromium and chromium-driver for eyeview's browser test.
set -euo pipefail

apt_packages=(cmake ninja-build g++ ccache pkg-config clang-format
              libglm-dev libembree-dev libosd-dev libopenexr-dev libimath-dev libtbb-dev catch2 libjpeg62-turbo-dev
              libopenimageio-dev openimageio-tools libkissfft-dev
              chromium chromium-driver)  # chromium: the headless browser eyeview's page is tested in

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

# Python side (the eyerender package and its tests). Where python3 is pyenv's (this project's
# machines), packages go there; where it is Debian's externally managed /usr/bin/python3, into a
# project venv, .venv/, which `make test` then uses.
PYTHON=${PYTHON:-python3}
if [[ $(command -v "$PYTHON") == /usr/bin/* ]]; then
  if [[ ! -x .venv/bin/python ]]; then
    # python3-dev: Python.h, for building the eyerender extension against Debian's interpreter.
    for p in python3-venv python3-dev; do
      dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
        { apt-get update -qq && apt-get install -y -qq --no-install-recommends "$p" >/dev/null; }
    done
    "$PYTHON" -m venv .venv
  fi
  PYTHON=.venv/bin/python
fi
pip_missing=()
"$PYTHON" -c "import pxr.Usd" 2>/dev/null || pip_missing+=(usd-core)
"$PYTHON" -c "import pytest" 2>/dev/null || pip_missing+=(pytest)
"$PYTHON" -c "import jinja2" 2>/dev/null || pip_missing+=(jinja2)  # usdGenSchema, for the schema consistency test
"$PYTHON" -c "import numpy" 2>/dev/null || pip_missing+=(numpy)
"$PYTHON" -c "import matplotlib" 2>/dev/null || pip_missing+=("matplotlib>=3.5")  # eyestudy's plot
# The farm extra (eyerender[farm]: eyerecord --scheduler/--workers), so tests/python/test_farm.py runs.
"$PYTHON" -c "import dask, distributed" 2>/dev/null || pip_missing+=("dask[distributed]>=2024.1")
# eyerecord --denoise: Intel Open Image Denoise with its CPU device, bundled in the wheel.
"$PYTHON" -c "import pyoidn" 2>/dev/null || pip_missing+=("pyoidn>=2.5")
# The eyerender package's build backend, installed here so `pip install --no-build-isolation .` needs no download.
"$PYTHON" -c "import nanobind" 2>/dev/null || pip_missing+=("nanobind>=2.0")
"$PYTHON" -c "import scikit_build_core" 2>/dev/null || pip_missing+=("scikit-build-core>=0.10")
# The linter `make lint` and `make test` run; its rules change between minor versions, so the minor is pinned.
"$PYTHON" -m ruff --version 2>/dev/null | grep -q "^ruff 0\.17\." || pip_missing+=("ruff>=0.17,<0.18")
# bench/bench_iris.py reads EXR renders (its plot uses matplotlib, above).
"$PYTHON" -c "import OpenEXR" 2>/dev/null || pip_missing+=(openexr)
# tests/python/test_eyeview_browser.py drives Debian's chromium through its chromedriver.
"$PYTHON" -c "import selenium" 2>/dev/null || pip_missing+=("selenium>=4.10")
if ((${#pip_missing[@]})); then
  echo "install_deps: pip installing ${pip_missing[*]}"
  "$PYTHON" -m pip install --quiet --disable-pip-version-check --root-user-action=ignore "${pip_missing[@]}"
fi
