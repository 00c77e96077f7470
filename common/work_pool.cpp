#include "common/work_pool.hpp"

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace mufric {

void run_work_pool(size_t count, int workers, const std::function<bool(size_t k)>& work) {
  std::atomic<size_t> next{0};
  std::atomic<bool> stop{false};
  auto worker = [&] {
    while (!stop) {
      const size_t k = next++;
      if (k >= count) return;
      if (!work(k)) stop = true;
    }
  };
  const auto threads = static_cast<int>(std::min<size_t>(static_cast<size_t>(std::max(workers, 1)), std::max<size_t>(count, 1)));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

}  // namespace mufric
