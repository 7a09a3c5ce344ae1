#!/usr/bin/env bash
# Sets up hdVolPhoton on a fresh Debian 12 machine: Debian packages, a Python virtual environment in
# .venv with the `volphoton` package (pip builds the C++ core through scikit-build-core), and the
# CMake build of the core, its tests and tools in build/.
#
#   tools/setup.sh            # everything
#   VOLPHOTON_SKIP_APT=1 tools/setup.sh   # when the packages are already there (no root needed)
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES=(
  build-essential cmake ninja-build pkg-config python3-venv python3-dev
  libembree-dev libopenvdb-dev libboost-iostreams-dev libopenexr-dev libimath-dev libtbb-dev
  libopencolorio-dev libtinygltf-dev libgtest-dev
)
if [ -z "${VOLPHOTON_SKIP_APT:-}" ]; then
  missing=()
  for p in "${APT_PACKAGES[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing Debian packages: ${missing[*]}"
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${missing[@]}"
  fi
fi

PYTHON=${PYTHON:-python3}
[ -d .venv ] || "$PYTHON" -m venv .venv
# shellcheck disable=SC1091
. .venv/bin/activate
pip install -q --upgrade pip
pip install -q "scikit-build-core>=0.10" "pybind11>=2.12" numpy "usd-core>=24.8" Pillow pytest jinja2 iadpython scipy matplotlib
echo "setup: building and installing the volphoton Python package (C++ core + bindings)"
CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)} pip install -q --no-build-isolation .

echo "setup: building the C++ core, its tests and tools in build/"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build
[ -f testenv/cloud.vdb ] || python tools/make_cloud_vdb.py testenv/cloud.vdb
python tools/make_gltf_assets.py testenv/gltf >/dev/null   # the glTF example asset, converted
echo "setup: done. Activate with: . .venv/bin/activate"
