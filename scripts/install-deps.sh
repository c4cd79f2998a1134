#!/usr/bin/env bash
# Installs the Debian 12 packages diffpills needs, but only those that are missing, so that
# `make test` and `make demo` work on a fresh machine and cost nothing on a prepared one.
# Uses sudo when not run as root. The package list is DESIGN.md section 6.
set -euo pipefail

packages=(
  build-essential cmake
  libeigen3-dev          # linear algebra
  libhwy-dev             # Google Highway: SIMD with run-time dispatch (the capsule batches)
  libgtest-dev           # unit tests
  libbenchmark-dev       # benchmarks
  libfcl-dev             # independent distances for tests and benchmarks
  libtbb-dev             # oneTBB, measured beside the batches' worker pool in the benchmarks
  nlohmann-json3-dev     # JSON for `diffpills query`
  coinor-libipopt-dev    # NLP cross-check of the trajectory optimizer
  pkg-config             # finds Ipopt
  librsvg2-bin           # rsvg-convert: lets a person look at the demo's SVG figures as PNG
  python3-dev pybind11-dev  # the Python bindings
  python3-numpy python3-pytest python3-torch python3-matplotlib  # their tests and example
  python3-mpmath         # 50-digit references in the Python tests
  clang-14 libfuzzer-14-dev  # the fuzz targets (make fuzz)
  python3-venv python3-pip python3-setuptools  # the tested `pip install --no-build-isolation .`
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ "${#missing[@]}" -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
