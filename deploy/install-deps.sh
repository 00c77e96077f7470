#!/usr/bin/env bash
# Installs every Debian 12 package mufric's build, tests and benchmarks need.
# Idempotent: packages already present are skipped, so a second run costs one dpkg query.
# Run as root (or with sudo available) on a fresh Debian 12 machine.
set -euo pipefail

# What to install: "all" (default: build, tests, benchmarks, fuzzing, Slurm and container tests) or
# "build" (only what compiling the mufric executable needs, e.g. inside deploy/Dockerfile).
profile=${1:-all}
build_packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git
  # numerical core
  libeigen3-dev libsuitesparse-dev libnlopt-dev libnlopt-cxx-dev libboost-dev
  # files and command line
  libhdf5-dev nlohmann-json3-dev libcli11-dev libssl-dev
  # the service: gRPC + Protobuf
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc
  # LAPACK (Cholesky, inverse) from OpenBLAS
  libopenblas-dev
)
test_packages=(
  libgtest-dev libgmock-dev libbenchmark-dev hdf5-tools openssl
  # Python clients and Fortran for the Fortran client
  python3-grpcio python3-grpc-tools gfortran
  # benchmark peer (scikit-learn on OpenBLAS) and plots; run with /usr/bin/python3
  python3-sklearn python3-numpy python3-h5py python3-matplotlib libopenblas0-pthread
  # fuzzing: clang with libFuzzer and its OpenMP runtime (tests/fuzz, a second build)
  clang-14 libclang-rt-14-dev libfuzzer-14-dev libomp-14-dev
  # a single-node Slurm cluster for the array-job integration test (deploy/slurm)
  slurm-wlm munge
  # the container test: podman with runc, and mmdebstrap for a base image made offline
  podman runc uidmap mmdebstrap
)
case $profile in
  all) packages=("${build_packages[@]}" "${test_packages[@]}") ;;
  build) packages=("${build_packages[@]}") ;;
  *) echo "install-deps: unknown profile '$profile' (all or build)" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
