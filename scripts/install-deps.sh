#!/usr/bin/env bash
# Installs every Debian package cleave needs to build, test and run (idempotent, non-interactive).
# Usage: scripts/install-deps.sh            (needs root or sudo; does nothing when all are present)
set -euo pipefail

packages=(
  # toolchain
  cmake ninja-build g++ clang libclang-rt-14-dev pkg-config
  # numerics and utilities
  libeigen3-dev libtbb-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libsuitesparse-dev
  # optimized BLAS/LAPACK for CHOLMOD's supernodal factorization (the reference libblas3 is ~5-10x slower)
  libopenblas0-pthread
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev gnuplot-nox
  # model formats: volumes (NRRD, NIfTI), meshes, voxelization
  zlib1g-dev libteem-dev libnifti2-dev libassimp-dev libopenvdb-dev
  # studio server (Boost.Beast is header-only in libboost-dev)
  libboost-dev
  # browser tests
  chromium
  # real data the tests load: the Colin27 head MRI and CGAL's closed human-body mesh
  mricron-data libcgal-demo
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# Node.js and npm (for the browser tests) come with the machine image; Debian's nodejs is the fallback.
command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
