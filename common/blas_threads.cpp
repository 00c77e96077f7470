#include "common/blas_threads.hpp"

#include <mutex>

extern "C" {
int openblas_get_num_threads(void);
void openblas_set_num_threads(int);
}

namespace mufric {
namespace {

// OpenBLAS's thread count is one per process, while guards live in several threads at once (the
// draws of a μ measurement run side by side). Each guard restoring what it found let the first draw
// to finish give the other its threads back in the middle of its run, at a moment the scheduler
// chose, so the last digits of a run changed from run to run (and a lubricated μ with them). The
// count is therefore taken by the first guard alive and given back by the last one.
std::mutex guard_mutex;
int guards_alive = 0;
int threads_before_guards = 1;

}  // namespace

SingleThreadedBlas::SingleThreadedBlas() {
  const std::lock_guard lock(guard_mutex);
  if (guards_alive++ == 0) {
    threads_before_guards = openblas_get_num_threads();
    openblas_set_num_threads(1);
  }
}

SingleThreadedBlas::~SingleThreadedBlas() {
  const std::lock_guard lock(guard_mutex);
  if (--guards_alive == 0) openblas_set_num_threads(threads_before_guards);
}

int blas_threads() { return openblas_get_num_threads(); }

}  // namespace mufric
