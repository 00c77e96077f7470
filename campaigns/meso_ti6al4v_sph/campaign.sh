#!/usr/bin/env bash
# Runs the meso-code comparison's runs (runs.csv) one after another on one core, each resumed from its
# checkpoint, skipping those done (runs/NAME/summary.json). Never part of CI: hours of runs.
#
#   nohup bash campaigns/meso_ti6al4v_sph/campaign.sh [--core 1] [--only NAME] > campaign.log 2>&1 &
#   kill -TERM <pid>   stops the running run at its next checkpoint (within a bin of travel)
#
# It uses a frozen copy of mfree_cut, of the libmufric it links and of the shipped models (bin/, with
# the patch's and the models' sha256 beside them), so that rebuilding mufric or the coupling while it
# runs changes nothing; a later change of the coupling's patch is refused until bin/ is removed on
# purpose (which makes the runs' results mixed). Build first:
#   bash examples/meso/mfree_iwf-ul-cut-refine/build.sh --upstream SRC
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
core=1 only=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --core) core=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "campaign.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
patch_file=$root/examples/meso/mfree_iwf-ul-cut-refine/mufric-coupling.patch
built=$root/build-meso/build/mfree_cut
prefix=$root/build-meso/mufric-prefix
mkdir -p "$here/bin" "$here/runs"
patch_sha=$(sha256sum "$patch_file" | cut -d' ' -f1)
if [[ ! -x $here/bin/mfree_cut ]]; then
  [[ -x $built ]] || { echo "campaign.sh: no $built (run build.sh first)" >&2; exit 2; }
  mkdir -p "$here/bin/lib" "$here/bin/models"
  cp -a "$prefix"/lib/libmufric.so* "$here/bin/lib/"
  cp "$prefix"/share/mufric/models/*.h5 "$here/bin/models/"
  cp "$built" "$here/bin/mfree_cut"
  echo "$patch_sha" > "$here/bin/patch.sha256"
  (cd "$here/bin/models" && sha256sum ./*.h5) > "$here/bin/models.sha256"
fi
models=$here/bin/models
export LD_LIBRARY_PATH=$here/bin/lib
if [[ $(cat "$here/bin/patch.sha256") != "$patch_sha" ]]; then
  echo "campaign.sh: the coupling's patch changed since bin/mfree_cut was frozen; remove bin/ to rebuild on purpose" >&2
  exit 2
fi
stop=0
trap 'stop=1; [[ -n ${child:-} ]] && kill -TERM "$child" 2>/dev/null' TERM INT
while IFS=, read -r name options; do
  [[ -z $name || $name == \#* || $name == name ]] && continue
  [[ -n $only && $name != "$only" ]] && continue
  out=$here/runs/$name
  [[ -f $out/summary.json ]] && continue
  options=${options//MODELS/$models}
  options=${options//DATA/$root/data}
  options=${options//OUT/$out}
  echo "$(date -u +%FT%TZ) $name: mfree_cut $options"
  # shellcheck disable=SC2086
  taskset -c "$core" "$here/bin/mfree_cut" $options --out "$out" >> "$here/runs/$name.log" 2>&1 &
  child=$!
  wait "$child"; rc=$?
  child=""
  echo "$(date -u +%FT%TZ) $name: exit $rc"
  [[ $stop == 1 || $rc == 3 ]] && break
  [[ $rc != 0 ]] && echo "$(date -u +%FT%TZ) $name failed (see runs/$name.log); next run"
done < "$here/runs.csv"
