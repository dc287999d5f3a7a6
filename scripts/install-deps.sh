#!/usr/bin/env bash
# Installs every Debian package piola needs to build, test and run its examples.
# Safe to run again: apt-get skips what is already installed.
set -euo pipefail

packages=(
  # build
  build-essential cmake pkg-config
  clang libclang-rt-dev libomp-dev
  # libraries piola links against
  libcjson-dev libpng-dev libsuitesparse-dev
  # unit-test framework (run through ctest)
  libcmocka-dev
  # external tools the round-trip tests talk to
  gmsh tetgen python3 python3-meshio python3-vtk9 python3-numpy
  # the Python package (python/): the C extension's headers, its tests and the plotting example
  python3-dev python3-pytest python3-matplotlib
  # movies from `piola render`
  ffmpeg
  # MPI domain decomposition (docs/mpi.md): OpenMPI and METIS graph partitions
  libopenmpi-dev openmpi-bin libmetis-dev
  # the implicit integrators' Newton systems on several MPI processes (docs/mpi.md)
  petsc-dev
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
