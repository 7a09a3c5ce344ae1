#!/usr/bin/env bash
# Sets up hdVolPhoton on a fresh Debian 12 machine: Debian packages, a Python virtual environment in
# .venv with the `volphoton` package (pip builds the C++ core through scikit-build-core), and the
# CMake build of the core, its tests and tools in build/ -- with the Hydra delegate when an OpenUSD
# with imaging is there.
#
# OpenUSD: an OpenUSD with imaging is looked for where CMake looks ($PXR_ROOT, $pxr_DIR, /usr/local,
# /opt/openusd, /opt/USD, ~/openusd). When there is none and the prebuilt OpenUSD 24.08 tarball lies
# beside the repository (../shared/openusd/, see its README), this installs its Debian packages
# (runtime and build), unpacks it to /opt/openusd (kept when already there and complete), lets
# Debian's /usr/bin/python3 find its pxr (a .pth file) and installs PySide6 and PyOpenGL for that
# Python (usdview). Without either, the build and tools/test.sh skip the delegate in one line.
#
#   tools/setup.sh            # everything
#   VOLPHOTON_SKIP_APT=1 tools/setup.sh   # when the Debian packages are already there
set -euo pipefail
cd "$(dirname "$0")/.."
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"

APT_PACKAGES=(
  build-essential cmake ninja-build pkg-config python3-venv python3-dev
  libembree-dev libopenvdb-dev libboost-iostreams-dev libopenexr-dev libimath-dev libtbb-dev
  libopencolorio-dev libtinygltf-dev libgtest-dev
)
# The prebuilt OpenUSD's packages (../shared/openusd/README.md: runtime, then what building against
# it needs).
OPENUSD_APT_PACKAGES=(
  libtbb12 libboost-python1.74.0 libosdcpu3.5.0 libosdgpu3.5.0 libgl1 libx11-6 libgomp1 libpython3.11 python3
  libtbb-dev libboost-python-dev libosd-dev libgl1-mesa-dev libx11-dev python3-dev
)
# What the usdview test needs with any OpenUSD that has usdview: a virtual X server, Mesa's software
# GL, pip for Debian's Python (it has none of its own), the X libraries of PySide6's xcb plug-in.
USDVIEW_TEST_APT_PACKAGES=(
  xvfb xauth libgl1-mesa-dri python3-pip
  libegl1 libfontconfig1 libdbus-1-3 libxkbcommon0 libxkbcommon-x11-0 libxcb-cursor0 libxcb-icccm4 libxcb-image0
  libxcb-keysyms1 libxcb-randr0 libxcb-render-util0 libxcb-shape0 libxcb-xkb1
)
OPENUSD_TARBALL=$(cd .. && pwd)/shared/openusd/openusd-24.08-debian12-x86_64.tar.xz
OPENUSD_PREFIX=/opt/openusd

# An OpenUSD install root with Hd and UsdImaging (headers and pxrConfig.cmake), as CMake would find it.
openusd_with_imaging() {
  local d
  for d in "${PXR_ROOT:-}" "${pxr_DIR:-}" /usr/local /opt/openusd /opt/USD "$HOME/openusd"; do
    [ -n "$d" ] && [ -f "$d/pxrConfig.cmake" ] && [ -d "$d/include/pxr/imaging/hd" ] &&
      [ -d "$d/include/pxr/usdImaging/usdImaging" ] && { echo "$d"; return 0; }
  done
  return 1
}
# Complete: what the delegate, usdrecord and usdview need (an interrupted unpack lacks some).
openusd_complete() {
  [ -f "$1/pxrConfig.cmake" ] && [ -x "$1/bin/usdrecord" ] && [ -x "$1/bin/usdview" ] &&
    [ -d "$1/lib/python/pxr/Usdviewq" ] && [ -d "$1/include/pxr/usdImaging/usdImaging" ]
}

PXR_FOUND=$(openusd_with_imaging || true)
if [ "$PXR_FOUND" = "$OPENUSD_PREFIX" ] && [ -f "$OPENUSD_TARBALL" ] && ! openusd_complete "$PXR_FOUND"; then
  PXR_FOUND=""  # an interrupted unpack of the tarball: unpacked again below
fi
USE_TARBALL=""
if [ -z "$PXR_FOUND" ] && [ -f "$OPENUSD_TARBALL" ]; then
  if [ "$(uname -m)" = x86_64 ] && grep -q '^VERSION_ID="12"' /etc/os-release 2>/dev/null; then
    USE_TARBALL=1
    APT_PACKAGES+=("${OPENUSD_APT_PACKAGES[@]}" "${USDVIEW_TEST_APT_PACKAGES[@]}")
  else
    echo "setup: $OPENUSD_TARBALL is built for Debian 12 x86-64; not used here (Hydra delegate skipped)"
  fi
elif [ -n "$PXR_FOUND" ] && [ -x "$PXR_FOUND/bin/usdview" ]; then
  APT_PACKAGES+=("${USDVIEW_TEST_APT_PACKAGES[@]}")
fi

if [ -z "${VOLPHOTON_SKIP_APT:-}" ]; then
  missing=()
  for p in "${APT_PACKAGES[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing Debian packages: ${missing[*]}"
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${missing[@]}"
  fi
fi

# (A complete /opt/openusd was found above and is kept.)
if [ -n "$USE_TARBALL" ]; then
  echo "setup: unpacking $OPENUSD_TARBALL to $OPENUSD_PREFIX"
  parent=$(dirname "$OPENUSD_PREFIX")
  tmp=$($SUDO mktemp -d "$parent/.openusd-unpack.XXXXXX")
  $SUDO tar -xJf "$OPENUSD_TARBALL" -C "$tmp"   # the tarball holds one folder, openusd/
  openusd_complete "$tmp/openusd" || { echo "setup: the tarball did not unpack completely" >&2; exit 1; }
  if [ -e "$OPENUSD_PREFIX" ]; then  # an earlier, interrupted unpack: kept aside, not deleted
    echo "setup: $OPENUSD_PREFIX is incomplete; moved to $OPENUSD_PREFIX.incomplete.$$"
    $SUDO mv "$OPENUSD_PREFIX" "$OPENUSD_PREFIX.incomplete.$$"
  fi
  $SUDO mv "$tmp/openusd" "$OPENUSD_PREFIX"
  $SUDO rmdir "$tmp"
  PXR_FOUND=$OPENUSD_PREFIX
fi

if [ -n "$PXR_FOUND" ] && [ -x "$PXR_FOUND/bin/usdview" ]; then
  usdview_python=$(head -1 "$PXR_FOUND/bin/usdview" | sed 's/^#! *//; s/^\/usr\/bin\/env  *//')
  # usdrecord and usdview of the prebuilt OpenUSD run on Debian's /usr/bin/python3 (its
  # pxrConfig.cmake names it): let that Python find OpenUSD's pxr. Never PYTHONPATH: the venv's
  # usd-core has a pxr of its own.
  if [ "$usdview_python" = /usr/bin/python3 ] && [ -d "$PXR_FOUND/lib/python/pxr" ] &&
     ! /usr/bin/python3 -c "import pxr.UsdAppUtils" >/dev/null 2>&1; then
    echo "setup: $PXR_FOUND/lib/python -> /usr/lib/python3/dist-packages/openusd.pth"
    echo "$PXR_FOUND/lib/python" | $SUDO tee /usr/lib/python3/dist-packages/openusd.pth >/dev/null
  fi
  # usdview's Qt and GL bindings, for the Python its script names (Debian's: pip needs
  # --break-system-packages there). Versions as tested with OpenUSD 24.08.
  if ! $usdview_python -c "import PySide6.QtOpenGLWidgets, OpenGL.GL" >/dev/null 2>&1; then
    echo "setup: installing PySide6-Essentials and PyOpenGL for $usdview_python (usdview)"
    $SUDO $usdview_python -m pip install -q --break-system-packages --root-user-action=ignore \
      "PySide6-Essentials==6.12.0" "PyOpenGL==3.1.10"
  fi
fi

PYTHON=${PYTHON:-python3}
[ -d .venv ] || "$PYTHON" -m venv .venv
# shellcheck disable=SC1091
. .venv/bin/activate
pip install -q --upgrade pip
pip install -q "scikit-build-core>=0.10" "pybind11>=2.12" numpy "usd-core>=24.8" Pillow pytest jinja2 iadpython scipy matplotlib
# Optional: Intel Open Image Denoise for `volphoton render --denoise` (the `oidn` wheel ships the
# library; volphoton/denoise.py loads it). Without it --denoise says what to install.
pip install -q oidn || echo "setup: the optional denoiser (pip package oidn) could not be installed; --denoise will say so"
echo "setup: building and installing the volphoton Python package (C++ core + bindings)"
CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)} pip install -q --no-build-isolation .

echo "setup: building the C++ core, its tests and tools in build/"
pxr_flag=(); [ -n "$PXR_FOUND" ] && pxr_flag=(-Dpxr_DIR:PATH="$PXR_FOUND")
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "${pxr_flag[@]}" >/dev/null
cmake --build build
[ -f testenv/cloud.vdb ] || python tools/make_cloud_vdb.py testenv/cloud.vdb
python tools/make_gltf_assets.py testenv/gltf >/dev/null   # the glTF example asset, converted
echo "setup: done. Activate with: . .venv/bin/activate"
