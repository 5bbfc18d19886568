#!/usr/bin/env bash
# Installs the Debian packages amcodec builds with, skipping those already present.
set -euo pipefail
packages=(g++ cmake make pkg-config libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
          libmeshoptimizer-dev libxxhash-dev zlib1g-dev
          pybind11-dev python3-dev python3-numpy python3-pytest python3-meshio python3-vtk9)
# --bench: the peers of bench/compare_bench; --p4est: octree interoperability; --mpi: Open MPI for
# amcodec_mpi; --fuzz: clang and its libFuzzer runtime (tests/fuzz); --compat: what the older commits
# that scripts/check_old_versions.sh builds need (their OBJ reader was tinyobjloader).
for arg in "$@"; do
  case "$arg" in
    --bench) packages+=(libdraco-dev libzstd-dev liblzma-dev libzfp-dev python3) ;;
    --p4est) packages+=(libp4est-dev libopenmpi-dev) ;;  # cmake -DAMC_WITH_P4EST=ON (octree forests)
    --mpi) packages+=(libopenmpi-dev openmpi-bin) ;;     # cmake -DAMC_WITH_MPI=ON (amcodec_mpi, mpirun for its tests)
    --fuzz) packages+=(clang libclang-rt-14-dev) ;;
    --compat) packages+=(libtinyobjloader-dev) ;;
  esac
done
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  $sudo apt-get update
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends "${missing[@]}"
fi
