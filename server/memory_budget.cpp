#include "server/memory_budget.hpp"

#include <malloc.h>

namespace mufric::server {

MemoryBudget::Reservation& MemoryBudget::Reservation::operator=(Reservation&& other) noexcept {
  if (this != &other) {
    release();
    budget_ = other.budget_;
    bytes_ = other.bytes_;
    other.budget_ = nullptr;
  }
  return *this;
}

void MemoryBudget::Reservation::release() {
  if (budget_ != nullptr) budget_->release(bytes_);
  budget_ = nullptr;
}

MemoryBudget::Reservation MemoryBudget::try_reserve(std::size_t bytes) {
  std::lock_guard lock(mutex_);
  if (limit_ > 0 && in_use_ > 0 && in_use_ + bytes > limit_) return {};
  in_use_ += bytes;
  since_idle_ += bytes;
  return {this, bytes};
}

std::size_t MemoryBudget::in_use() const {
  std::lock_guard lock(mutex_);
  return in_use_;
}

void MemoryBudget::release(std::size_t bytes) {
  bool trim = false;
  {
    std::lock_guard lock(mutex_);
    in_use_ -= bytes;
    if (in_use_ == 0) {
      trim = since_idle_ >= trim_after_;
      since_idle_ = 0;
    }
  }
  // glibc keeps freed memory in its arenas (one per thread that allocated: gRPC's threads each
  // have one), so a burst's peak stayed resident when idle. malloc_trim(0) gives the free pages of
  // every arena back (glibc manual, "Memory Allocation Tunables"; malloc_trim(3)); it takes
  // milliseconds, once per burst.
  if (trim) {
    malloc_trim(0);
    ++trims_;
  }
}

}  // namespace mufric::server
