#!/usr/bin/env bash
# Builds mfree_iwf-ul-cut-refine at the commit this coupling was written against, with the coupling's
# patch applied, linked to mufric's C ABI (libmufric.so): the executables mfree_cut (the coupled cut)
# and refine_paper (upstream's own models).
#
#   bash build.sh --upstream SRC [--mufric-build DIR] [--out DIR]
#     SRC  a clone of https://github.com/iwf-inspire/mfree_iwf-ul-cut-refine (any branch; the commit
#          below is checked out from it)
#     --mufric-build DIR   mufric's CMake build tree (default: the repository's build/), installed
#                          into OUT/mufric-prefix for find_package(mufric)
#     --out DIR            where the patched source and the build go (default: build-meso/ at the
#                          repository's root)
#   Environment: MFREE_MAX_NBH (neighbour slots per particle, default 64; upstream 600: same results,
#   1.4x slower here), MUFRIC_JOBS (default 2).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
upstream_commit=e8dd8f8483414118369616767ad25192bc839b89
src="" mufric_build="$root/build" out="$root/build-meso"
while [[ $# -gt 0 ]]; do
  case $1 in
    --upstream) src=$2; shift 2 ;;
    --mufric-build) mufric_build=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "build.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[[ -n $src ]] || { echo "build.sh: --upstream SRC is required (a clone of iwf-inspire/mfree_iwf-ul-cut-refine)" >&2; exit 2; }
git -C "$src" cat-file -e "$upstream_commit^{commit}" 2>/dev/null ||
  { echo "build.sh: $src has no commit $upstream_commit" >&2; exit 2; }
[[ -f $mufric_build/CMakeCache.txt ]] || { echo "build.sh: $mufric_build is not a configured mufric build (cmake -S . -B build first)" >&2; exit 2; }
dpkg -s libglm-dev >/dev/null 2>&1 || { apt-get update -qq && apt-get install -y -qq libglm-dev >/dev/null; }

mkdir -p "$out"
rm -rf "$out/source"
git -C "$src" archive --format=tar --prefix=source/ "$upstream_commit" | tar -x -C "$out"
(cd "$out/source" && patch -p1 --quiet < "$here/mufric-coupling.patch")
cmake --install "$mufric_build" --prefix "$out/mufric-prefix" >/dev/null
cmake -S "$out/source" -B "$out/build" -DCMAKE_PREFIX_PATH="$out/mufric-prefix" -DMUFRIC_GLUE_DIR="$here/glue" \
  -DMFREE_MAX_NBH="${MFREE_MAX_NBH:-64}" >/dev/null
cmake --build "$out/build" -j "${MUFRIC_JOBS:-2}"
echo "build.sh: $out/build/mfree_cut (models: $out/mufric-prefix/share/mufric/models)"
