#pragma once
// What the environment says: diagnostic switches (MUFRIC_TRACE_NEWTON, MUFRIC_TRACE_COUPLING, …) and
// how many cores this process may use.
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>

namespace mufric {

// true when the variable is set and neither empty nor starting with '0'.
inline bool environment_flag(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' && *v != '0';
}

// The default thread count of every command: the CPUs of this process's affinity mask (taskset,
// cgroup cpusets, a batch scheduler's binding), at most OMP_NUM_THREADS when that is set. Not
// std::thread::hardware_concurrency() nor omp_get_num_procs(): the first counts the machine's CPUs
// (under `taskset -c 0` on 2 cores it said 2, and two threads then shared one core), and OpenMP's
// own count ignores OMP_NUM_THREADS. OMP_NUM_THREADS may be a list ("4,2": per nesting level); its
// first entry is the outer team's. At least 1.
inline int usable_cores() {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  // A machine of more than CPU_SETSIZE (1024) CPUs fails the call: then every online CPU counts.
  int cores = sched_getaffinity(0, sizeof mask, &mask) == 0 ? CPU_COUNT(&mask)
                                                             : static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  cores = std::max(1, cores);
  if (const char* omp = std::getenv("OMP_NUM_THREADS"); omp != nullptr) {
    char* end = nullptr;
    errno = 0;
    const long requested = std::strtol(omp, &end, 10);
    const bool valid = end != omp && errno == 0 && requested > 0 && (*end == '\0' || *end == ',');
    if (valid) cores = static_cast<int>(std::min<long>(cores, requested));  // an invalid value is ignored, as OpenMP does
  }
  return cores;
}

}  // namespace mufric
