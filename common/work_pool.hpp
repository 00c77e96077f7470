#pragma once
// One work pool for the project's independent jobs (a measurement's draws, a campaign's samples):
// `workers` threads, the calling thread one of them, each taking the next index in order.
#include <cstddef>
#include <functional>

namespace mufric {

// Runs work(k) for k = 0 … count − 1 on min(workers, count) threads (at least the caller's). work
// returning false stops the pool: no index is taken after it (those already running finish). An
// exception thrown by work is the caller's bug to avoid: catch inside work and record the failure.
void run_work_pool(size_t count, int workers, const std::function<bool(size_t k)>& work);

}  // namespace mufric
