#!/usr/bin/env bash
# Installs mufric into a temporary prefix and builds tests/package_consumer from scratch against
# it with find_package(mufric), then runs it on a seed-001 law file.
set -euo pipefail
build_dir=$1 source_dir=$2 mufric=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
cmake -S "$source_dir/tests/package_consumer" -B "$work/build" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" >/dev/null
"$mufric" law seward --table 4 --out "$work/law.h5" >/dev/null
"$work/build/meso" "$work/law.h5"
