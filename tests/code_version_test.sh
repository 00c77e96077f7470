#!/bin/bash
# cmake/MufricVersion.cmake, which writes the code version recorded in every model and dataset file,
# against git's own answer (rev-parse) in a scratch repository: the header follows a new commit and
# a dirty tree, is not rewritten when nothing changed (so nothing recompiles), and says "unknown"
# outside git. Usage: code_version_test.sh SOURCE_DIR
set -euo pipefail
script="$1/cmake/MufricVersion.cmake"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
header="$scratch/out/version.hpp"
write() { cmake -DSOURCE_DIR="$1" -DPROJECT_VERSION=9.8.7 -DOUTPUT="$header" -P "$script"; }
fail() { echo "FAIL: $*"; echo "header: $(cat "$header" 2>/dev/null)"; exit 1; }

repo="$scratch/repo"
mkdir -p "$repo" "$scratch/out"
git -C "$repo" init -q
git -C "$repo" -c user.name=t -c user.email=t@t commit -q --allow-empty -m first
write "$repo"
first=$(git -C "$repo" rev-parse --short HEAD)
grep -q "^#define MUFRIC_CODE_VERSION \"9.8.7+$first\"$" "$header" || fail "first commit $first not recorded"

written_at=$(stat -c %y "$header")
sleep 1.1
write "$repo"
[[ "$(stat -c %y "$header")" == "$written_at" ]] || fail "header rewritten although the version did not change"

git -C "$repo" -c user.name=t -c user.email=t@t commit -q --allow-empty -m second
write "$repo"
second=$(git -C "$repo" rev-parse --short HEAD)
[[ "$second" != "$first" ]] || fail "scratch commits have the same hash"
grep -q "\"9.8.7+$second\"" "$header" || fail "second commit $second not recorded (version frozen)"

echo x > "$repo/file" && git -C "$repo" add file
write "$repo"
grep -q "\"9.8.7+$second-dirty\"" "$header" || fail "uncommitted change not marked dirty"

mkdir -p "$scratch/plain"
GIT_CEILING_DIRECTORIES="$scratch" write "$scratch/plain"
grep -q "\"9.8.7+unknown\"" "$header" || fail "a tree without git should say unknown"
echo "code version header follows commits ($first, $second), dirty trees and unchanged builds"
