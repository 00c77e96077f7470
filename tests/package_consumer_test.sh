#!/usr/bin/env bash
# Installs mufric into a temporary prefix and builds meso-side consumers from scratch against it, as
# their authors would: CMake projects in C++ only (the C++ client), C only and Fortran only
# (mufric::mufric = libmufric.so), and a plain Makefile with pkg-config (C and Fortran). Each runs.
set -euo pipefail
build_dir=$1 source_dir=$2 mufric=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
cmake --install "$build_dir" --prefix "$prefix" >/dev/null

echo "== installed layout: headers only under include/mufric/"
ls "$prefix/include"
test "$(ls "$prefix/include")" = mufric
test -f "$prefix/include/mufric/mufric.h"
test -f "$prefix/lib/pkgconfig/mufric.pc"

echo "== models: a seed-001 law file, and a GP on seed 000's box"
"$mufric" law seward --table 4 --out "$work/law.h5" >/dev/null
"$mufric" law coulomb --mu 0.3 --out "$work/coulomb.h5" >/dev/null
"$mufric" dataset from-model --model "$work/coulomb.h5" --samples 60 --noise 0.01 --out "$work/data.h5" >/dev/null
"$mufric" train --data "$work/data.h5" --out "$work/gp.h5" --restarts 1 >/dev/null

echo "== CMake, C++ only: mufric::client"
cmake -S "$source_dir/tests/package_consumer" -B "$work/cxx" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/cxx" >/dev/null
"$work/cxx/meso" "$work/law.h5"

for language in c fortran; do
  if [ "$language" = fortran ] && ! command -v gfortran >/dev/null; then echo "no gfortran: Fortran consumer skipped"; continue; fi
  echo "== CMake, $language only: mufric::mufric"
  cmake -S "$source_dir/tests/package_consumer/$language" -B "$work/$language" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" \
    -DMUFRIC_EXAMPLES="$source_dir/examples" >/dev/null
  cmake --build "$work/$language" >/dev/null
  OMP_WAIT_POLICY=passive "$work/$language/meso_loop" "file://$work/gp.h5" 5 200
done

echo "== Makefile + pkg-config (C and Fortran)"
mkdir "$work/make"
PKG_CONFIG_PATH="$prefix/lib/pkgconfig" make -s -C "$work/make" -f "$source_dir/tests/package_consumer/Makefile" \
  EXAMPLES="$source_dir/examples" FC=gfortran
for program in meso_loop_c meso_loop_fortran; do
  OMP_WAIT_POLICY=passive "$work/make/$program" "file://$work/gp.h5" 5 200
done
echo "== the installed shipped model carries the fast evaluator the build tabulated"
"$mufric" describe "$prefix/share/mufric/models/dry_default.h5" | grep -q "measured bound" ||
  { echo "the installed dry_default.h5 has no fast evaluator"; exit 1; }
echo "== a shipped model's name reaches <prefix>/share/mufric/models of the installed library"
# The prefix here is not the one configured at build time, and the source tree is still there: the
# name must reach this prefix's file, which is made distinct (a Coulomb law, mu = 0.4321), from a
# working directory where a folder of the same name could shadow it.
"$mufric" law coulomb --mu 0.4321 --out "$prefix/share/mufric/models/dry_default.h5" >/dev/null
mkdir -p "$work/run/dry_default"
mu=$(cd "$work/run" && "$work/make/shipped_model" dry_default)
test "$mu" = 0.432100 || { echo "dry_default reached mu = $mu, not the installed prefix's 0.432100"; exit 1; }
echo "== Python in-process: the installed module finds the installed library by itself"
if /usr/bin/python3 -c "import numpy" 2>/dev/null; then
  mu=$(cd "$work/run" && env -u MUFRIC_LIBRARY PYTHONPATH="$prefix/share/mufric/python" /usr/bin/python3 -c "
from mufric_inprocess import open_model
with open_model('dry_default') as m:
    print('%.6f' % m.evaluate(contact_pressure=1e9, sliding_velocity=1.0, temperature=600.0).mu[0])")
  test "$mu" = 0.432100 || { echo "Python in-process reached mu = $mu, not the installed prefix's 0.432100"; exit 1; }
else
  echo "no numpy for /usr/bin/python3: the Python in-process module skipped"
fi
echo "== every consumer built and ran"
