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
  return {this, bytes};
}

std::size_t MemoryBudget::in_use() const {
  std::lock_guard lock(mutex_);
  return in_use_;
}

void MemoryBudget::release(std::size_t bytes) {
  std::lock_guard lock(mutex_);
  in_use_ -= bytes;
}

bool IdleTrimmer::poll(long long activity, bool idle) {
  if (!idle || activity == trimmed_at_) return false;
  malloc_trim(0);
  trimmed_at_ = activity;
  ++trims_;
  return true;
}

}  // namespace mufric::server
