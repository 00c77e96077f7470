#!/usr/bin/env bash
# Seeds, runs and triages mufric's libFuzzer targets (tests/fuzz/*.cpp, built by a clang build with
# -DMUFRIC_FUZZ=ON). Each target runs SECONDS in libFuzzer's fork mode, which survives crashes and
# keeps going; every crash, hang or out-of-memory input it saved is then replayed once and triaged by
# its stack: a fault whose first frame outside the sanitizer runtime and the C/C++ runtime lies in
# libhdf5 is the HDF5 library's own (mufric parses untrusted HDF5 in a child process for exactly this:
# common/isolation.hpp); any other is mufric's and fails the run.
# Seeds come from the project's own files: model files and datasets written by MUFRIC, the shipped
# scene, unit-annotated CSV tables and wire requests encoded with protoc.
# Usage: bash tests/fuzz/run_fuzzers.sh FUZZ_BUILD MUFRIC SECONDS OUT_DIR [TARGET...]
# Prints one line per target (executions, coverage, features, corpus, faults by owner); exit 1 when
# any fault is mufric's. MUFRIC_JOBS targets (default: the usable cores) fuzz side by side.
set -uo pipefail
if [[ $# -lt 4 || $1 == -h || $1 == --help ]]; then sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 2; fi
fuzz_build=$(realpath "$1") mufric=$(realpath "$2") seconds=$3 out=$4
shift 4
targets=("$@")
((${#targets[@]})) || targets=(fuzz_model_file fuzz_dataset_file fuzz_csv_table fuzz_scene_json fuzz_evaluate_request)
here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
mkdir -p "$out"
out=$(realpath "$out")

seed() {  # builds $out/seeds/<target>
  local s=$out/seeds
  [[ -d $s ]] && return
  mkdir -p "$s"/{fuzz_model_file,fuzz_dataset_file,fuzz_csv_table,fuzz_scene_json,fuzz_evaluate_request}
  local tmp
  tmp=$(mktemp -d)
  (
    cd "$tmp" || exit 1
    "$mufric" law seward --table 4 --out "$s/fuzz_model_file/mlr.h5" >/dev/null
    "$mufric" law coulomb --mu 0.3 --out "$s/fuzz_model_file/coulomb.h5" >/dev/null
    "$mufric" dataset from-model --model "$s/fuzz_model_file/mlr.h5" --samples 24 --noise 0.002 \
      --out "$s/fuzz_dataset_file/from-law.h5" >/dev/null
    "$mufric" train --data "$s/fuzz_dataset_file/from-law.h5" --out "$s/fuzz_model_file/gp.h5" >/dev/null
    "$mufric" dataset plan --out "$s/fuzz_dataset_file/plan.h5" --samples 4 >/dev/null
    printf 'contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n800,100,500,0.18\n300,22.5,25,0.25\n' \
      > "$s/fuzz_csv_table/gp.csv"
    printf '# tribometer\nfibre_angle[deg],sliding_velocity[m/min],contact_pressure[MPa],mu\n0,10,80,0.2\n90,20,60,0.25\n45,5,100,0.21\n' \
      > "$s/fuzz_csv_table/mlr.csv"
    cp "$source_dir/micro/scene/dry_default.json" "$s/fuzz_scene_json/"
    printf 'load.pressure=1300MPa' > "$s/fuzz_scene_json/override.txt"
    printf 'model: "gp" contact_pressure: [8e8, 3e8] sliding_velocity: [1.6, 0.4] temperature: [773, 300] std: true ci_level: 0.95 gradient: true\n' |
      protoc --encode=mufric.v1.EvaluateRequest -I "$source_dir/proto" mufric/v1/friction.proto > "$s/fuzz_evaluate_request/gp.bin"
    printf 'model: "coulomb" contact_pressure: [1e9] sliding_velocity: [-1] temperature: [nan]\n' |
      protoc --encode=mufric.v1.EvaluateRequest -I "$source_dir/proto" mufric/v1/friction.proto > "$s/fuzz_evaluate_request/bad.bin"
  )
  rm -rf "$tmp"
}

# The owner of a fault: an exception nobody caught is always mufric's (whoever threw it); otherwise
# the library of the first stack frame that is not the sanitizers' (their interceptors of malloc,
# str*, mem* included), libFuzzer's, main's or the C/C++ runtime's. For an out-of-memory report that
# is the first live allocation not made by libFuzzer itself.
owner() {  # log
  local frame
  if grep -qE 'std::terminate|__cxa_throw|uncaught exception' "$1"; then echo mufric; return; fi
  frame=$(grep -E '^ +#[0-9]+ ' "$1" |
          grep -vE 'libclang_rt|compiler-rt|sanitizer_common|/asan/|/ubsan/|libFuzzer|fuzzer/Fuzzer| in fuzzer::|libc\.so|nptl/|stdlib/|signal/|sysdeps/|libstdc\+\+|libgcc|in (abort|raise|__GI_|gsignal|malloc|free|calloc|realloc|operator new|operator delete|__interceptor_|__asan|__sanitizer|__ubsan|str[a-z]*|mem[a-z]*|main|_start)[ (]|in main \(|__libc_start| in (__sanitizer|__asan|__ubsan|__interceptor_|__lsan)' |
          head -1)
  if [[ -z $frame ]]; then echo unknown; elif [[ $frame == *libhdf5* || $frame == *H5* ]]; then echo hdf5; else echo mufric; fi
}

seed
status=0
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores; $seconds s per target"
echo
echo "| target | executions | exec/s | coverage (edges) | features | corpus | faults: HDF5 library | faults: mufric |"
echo "|---|---|---|---|---|---|---|---|"
fuzz() {  # target: SECONDS of libFuzzer in fork mode, log in $out/<target>.log
  local binary=$fuzz_build/tests/fuzz/$1 corpus=$out/corpus/$1 artifacts=$out/artifacts/$1
  mkdir -p "$corpus" "$artifacts"
  (cd "$out" && "$binary" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 -max_total_time="$seconds" \
      -timeout=5 -rss_limit_mb=2048 -artifact_prefix="$artifacts/" "$corpus" "$out/seeds/$1" > "$out/$1.log" 2>&1)
}
# Each target is one process (fork mode runs one job at a time): as many side by side as cores.
jobs=${MUFRIC_JOBS:-$(nproc)}
for target in "${targets[@]}"; do
  while (($(jobs -rp | wc -l) >= jobs)); do wait -n; done
  fuzz "$target" &
done
wait
for target in "${targets[@]}"; do
  binary=$fuzz_build/tests/fuzz/$target
  artifacts=$out/artifacts/$target
  last=$(grep -E '^#[0-9]+: cov: ' "$out/$target.log" | tail -1)
  execs=$(sed -nE 's/.*exec\/s:? ([0-9]+).*/\1/p' <<< "$last")
  runs=$(sed -nE 's/^#([0-9]+):.*/\1/p' <<< "$last")
  cov=$(sed -nE 's/.* cov: ([0-9]+).*/\1/p' <<< "$last")
  ft=$(sed -nE 's/.* ft: ([0-9]+).*/\1/p' <<< "$last")
  corp=$(sed -nE 's/.* corp: ([0-9]+).*/\1/p' <<< "$last")
  hdf5=0 ours=0
  for artifact in "$artifacts"/*; do
    [[ -f $artifact ]] || continue
    [[ $artifact == *.log ]] && continue
    (cd "$out" && timeout 60 "$binary" -timeout=10 -rss_limit_mb=2048 "$artifact" > "$artifact.log" 2>&1)
    if ! grep -qE 'ERROR: (AddressSanitizer|UndefinedBehaviorSanitizer|libFuzzer)|runtime error|SUMMARY' "$artifact.log"; then
      continue  # did not reproduce alone (a fork-mode job's accumulated state)
    fi
    case $(owner "$artifact.log") in
      hdf5) hdf5=$((hdf5 + 1)) ;;
      *) ours=$((ours + 1)); status=1; echo "mufric fault: $artifact (see $artifact.log)" >&2 ;;
    esac
  done
  printf '| %s | %s | %s | %s | %s | %s | %s | %s |\n' "$target" "${runs:-?}" "${execs:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" "$hdf5" "$ours"
done
exit $status
