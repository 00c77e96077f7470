# What every learner scenario (bench/scenarios/learn_*.sh) shares; sourced, defines functions only.
#
#   learn_common_option "$@" && { shift 2; continue; }   in an option loop: --mufric, --out, --rounds,
#                                                          --round-samples and --jobs set the variables of those names
#   prepare_learn_dir                                      empties $out and makes $out/served and $out/logs;
#                                                          py (Debian's python3) and PYTHONPATH for the client module
#   start_learning_server ARGS...                          `mufric serve` ARGS in the background, stopped on exit;
#                                                          sets address (bench/tools/service_common.sh)

# Returns 1 when $1 is not one of the shared options (the caller's own case handles it).
learn_common_option() {
  case $1 in
    --mufric) mufric=$2 ;;
    --out) out=$2 ;;
    --rounds) rounds=$2 ;;
    --round-samples) round_samples=$2 ;;
    --jobs) jobs=$2 ;;
    *) return 1 ;;
  esac
}

prepare_learn_dir() {
  py=/usr/bin/python3
  export PYTHONPATH=$here/build/python:$here/examples/python
  rm -rf "$out" && mkdir -p "$out/served" "$out/logs"
}

start_learning_server() {
  # shellcheck source=bench/tools/service_common.sh
  source "$here/bench/tools/service_common.sh"
  trap '[[ -z ${server:-} ]] || kill -TERM "$server" 2>/dev/null || true' EXIT
  start_server "$out" "$mufric" serve "$@"
}
