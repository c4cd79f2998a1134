#!/usr/bin/env bash
# The two ways the README installs the Python package, each checked by importing it from a fresh
# interpreter outside the source tree and running a query:
#   1. cmake --install of the build tree (configured with DIFFPILLS_PYTHON=ON) into a prefix;
#   2. pip install --no-build-isolation . into a venv that sees Debian's packages (offline).
# Arguments: the build directory, the source directory, the Python interpreter, the package's
# install directory relative to the prefix.
set -euo pipefail
build_dir="$1"
source_dir="$2"
python="$3"
relative_site="$4"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

check='import diffpills, diffpills.torch, torch
c = diffpills.Capsule(1.0, 0.1)
assert abs(diffpills.proximity(c, diffpills.Pose(), c, diffpills.Pose([0, 0, 1], [1, 0, 0, 0])).phi - 0.96) < 1e-12
phi = diffpills.torch.proximity(c, torch.zeros(2, 3), torch.tensor([1.0, 0, 0, 0]), c, torch.ones(2, 3), torch.tensor([1.0, 0, 0, 0]))
assert phi.shape == (2,)
print(diffpills.__file__)'

cmake --install "$build_dir" --prefix "$work/prefix" > install.log
PYTHONPATH="$work/prefix/$relative_site" "$python" -c "$check" | grep -q "$work/prefix/"
echo "cmake --install: imported from the prefix"

"$python" -m venv --system-site-packages "$work/venv"
CMAKE_BUILD_PARALLEL_LEVEL=2 "$work/venv/bin/pip" install --no-build-isolation --no-index \
  "$source_dir" > pip.log 2>&1 || { tail -30 pip.log; exit 1; }
"$work/venv/bin/python" -c "$check" | grep -q "$work/venv/"
echo "pip install --no-build-isolation: imported from the venv"
