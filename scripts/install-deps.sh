#!/usr/bin/env bash
# Install elastolearn's build and test dependencies from Debian packages.
# Skips everything already present; uses --no-install-recommends. Needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev            # dense/sparse linear algebra
  libsuitesparse-dev       # CHOLMOD supernodal Cholesky
  libopenblas0-pthread     # fast BLAS for CHOLMOD (4-11x over reference BLAS)
  libhdf5-dev              # trajectory / observation files
  libcli11-dev             # command line parsing
  nlohmann-json3-dev       # scene / material JSON
  libnanoflann-dev         # k-d trees
  libtbb-dev               # parallel element loops
  libembree-dev            # ray casting for the virtual depth scanner (Embree 3)
  libgtest-dev libgmock-dev libbenchmark-dev
  tetgen                   # external tetrahedralizer (AGPL: run as a program, never linked)
  clang-format             # scripts/check-format.sh (Debian 12's is version 14, the reference)
  python3-matplotlib       # the learning report's plots (report_plots.py, run by /usr/bin/python3)
  chromium                 # the report test opens report.html headless (WebGL); large, but CI needs it
  pybind11-dev python3-dev # the Python module (python/, docs/python.md)
  python3-numpy python3-pytest # its arrays and its tests (tests/python)
  python3-h5py             # the HDF5 interop test: h5py reads our files and we read its
)
# Real surface meshes for examples and benchmarks (optional; tests never need them).
if [[ "${ELASTOLEARN_WITH_CGAL_DATA:-1}" == 1 ]]; then packages+=(libcgal-demo); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
SUDO=""
if [[ $(id -u) != 0 ]]; then SUDO=sudo; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
