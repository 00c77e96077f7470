#!/usr/bin/env bash
# Installs every Debian 12 package mufric's build, tests and benchmarks need.
# Idempotent: packages already present are skipped, so a second run costs one dpkg query.
# Run as root (or with sudo available) on a fresh Debian 12 machine.
set -euo pipefail

packages=(
  # toolchain and test/bench frameworks
  build-essential cmake ninja-build pkg-config git
  libgtest-dev libgmock-dev libbenchmark-dev
  # numerical core
  libeigen3-dev libsuitesparse-dev libnlopt-dev libnlopt-cxx-dev libboost-dev
  # files and command line
  libhdf5-dev hdf5-tools nlohmann-json3-dev libcli11-dev libssl-dev openssl
  # the service: gRPC + Protobuf (C++ and Python), Fortran for the Fortran client
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc python3-grpcio python3-grpc-tools gfortran
  # LAPACK (Cholesky, inverse) from OpenBLAS
  libopenblas-dev
  # benchmark peer (scikit-learn on OpenBLAS) and plots; run with /usr/bin/python3
  python3-sklearn python3-numpy python3-h5py python3-matplotlib libopenblas0-pthread
  # fuzzing: clang with libFuzzer and its OpenMP runtime (tests/fuzz, a second build)
  clang-14 libclang-rt-14-dev libfuzzer-14-dev libomp-14-dev
  # a single-node Slurm cluster for the array-job integration test (deploy/slurm)
  slurm-wlm munge
)

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
