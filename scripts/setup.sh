#!/usr/bin/env bash
# Nimbus set-up, shared by run-demo.sh and run-tests.sh: installs the Debian
# packages Nimbus needs (only when one is missing), then configures and builds
# into ./build (incrementally). Safe to run again.
#
#   NIMBUS_BUILD_DIR   build directory (default: <repo>/build)
#   NIMBUS_JOBS        parallel build jobs (default: number of cores)
#   NIMBUS_OFFSCREEN   egl: no Xvfb (not installed, tests on EGL only)
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${NIMBUS_BUILD_DIR:-$repo/build}"
jobs="${NIMBUS_JOBS:-$(nproc)}"

# Debian bookworm packages. ParaView 5.11's SDK (paraview-dev) needs more than it
# depends on; this list is the one shared/SDK-NOTES.md records, plus the tools.
packages=(
  # ParaView and its VTK, for the plugin, Python and C++
  paraview paraview-dev python3-paraview
  # what paraview-dev's CMake config asks for without depending on it
  qtbase5-dev qttools5-dev libqt5svg5-dev libqt5opengl5-dev libqt5x11extras5-dev
  qtxmlpatterns5-dev-tools libhdf5-openmpi-dev libopenmpi-dev libutfcpp-dev
  libdouble-conversion-dev libgl2ps-dev libglew-dev libgdal-dev libnetcdf-dev
  libtheora-dev libavcodec-dev libavformat-dev libavutil-dev libswscale-dev
  libeigen3-dev libexpat1-dev libboost-dev libxml2-dev liblz4-dev liblzma-dev
  libjpeg-dev libpng-dev libtiff-dev libfreetype-dev zlib1g-dev libx11-dev libxt-dev
  libgl-dev python3-dev python3-mpi4py python3-numpy
  # build tools and tests
  cmake ninja-build g++ make libgtest-dev nlohmann-json3-dev python3-matplotlib
  libbenchmark-dev clang-format git
  # OpenVDB reader/writer (IO/) and the tests' independent .vdb producer
  libopenvdb-dev python3-openvdb
  # Data/UserData's LES-like NetCDF sample (scripts/make-user-sample-data.py)
  python3-netcdf4
  # headless OpenGL: Xvfb + Mesa llvmpipe
  xvfb libgl1-mesa-dri libglx-mesa0
  # driving and photographing the real GUI by hand (docs/images/gui: xdotool, import)
  xdotool imagemagick
  # no X at all: EGL (vtkNimbusOffscreenRenderWindow, NIMBUS_OFFSCREEN=egl)
  libegl-dev libegl-mesa0
  # ... or OSMesa, Mesa on the CPU into memory (NIMBUS_OFFSCREEN=osmesa, and where no EGL
  # display can be made); optional at configure time
  libosmesa6-dev
)

# NIMBUS_OFFSCREEN=egl: no X at all (a cluster node, a container): Xvfb is neither
# installed nor used, and the tests run on EGL only (docs/offscreen.md).
configure=()
if [ "${NIMBUS_OFFSCREEN:-}" = "egl" ]; then
  packages=("${packages[@]/xvfb/}")
  configure+=(-DNIMBUS_XVFB=OFF)
fi

missing=()
for package in "${packages[@]}"; do
  [ -n "$package" ] || continue
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if ((${#missing[@]})); then
  echo "nimbus setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# Debian's interpreter has python3-paraview's vtkmodules; another python3 first
# on PATH (pyenv, conda) would not.
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DPython3_EXECUTABLE=/usr/bin/python3 "${configure[@]}"
fi
cmake --build "$build" --parallel "$jobs"
