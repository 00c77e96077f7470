#pragma once
// The server's memory for requests in flight: each call reserves what it will hold (its request,
// its response and the response's serialised copy) before evaluating, and a call that does not fit
// is refused with RESOURCE_EXHAUSTED and a retry hint instead of growing the process without bound.
#include <atomic>
#include <cstddef>
#include <mutex>

namespace mufric::server {

class MemoryBudget {
 public:
  // A reservation: releases its bytes when destroyed (or moved from).
  class Reservation {
   public:
    Reservation() = default;
    Reservation(MemoryBudget* budget, std::size_t bytes) : budget_(budget), bytes_(bytes) {}
    Reservation(Reservation&& other) noexcept : budget_(other.budget_), bytes_(other.bytes_) { other.budget_ = nullptr; }
    Reservation& operator=(Reservation&& other) noexcept;
    Reservation(const Reservation&) = delete;
    Reservation& operator=(const Reservation&) = delete;
    ~Reservation() { release(); }
    void release();
    explicit operator bool() const { return budget_ != nullptr; }

   private:
    MemoryBudget* budget_ = nullptr;
    std::size_t bytes_ = 0;
  };

  // bytes 0: no limit.
  explicit MemoryBudget(std::size_t bytes) : limit_(bytes) {}

  // A reservation of `bytes`, or an empty one when it does not fit beside the calls in flight. A
  // call alone is always admitted, whatever its size: refusing it could never succeed later.
  Reservation try_reserve(std::size_t bytes);
  std::size_t in_use() const;
  std::size_t limit() const { return limit_; }

 private:
  void release(std::size_t bytes);

  const std::size_t limit_;
  mutable std::mutex mutex_;
  std::size_t in_use_ = 0;
};

// Gives the memory freed by a busy spell back to the system once, on the transition from busy to
// idle. glibc keeps freed memory in its arenas (one per thread that allocated: gRPC's threads each
// have one), so a burst's peak stayed resident when idle; malloc_trim(0) returns the free pages of
// every arena (malloc_trim(3)) in milliseconds. Once per spell: resident memory that a trim cannot
// lower (a larger model loaded) must not be trimmed again and again.
class IdleTrimmer {
 public:
  // `activity`: a count that grows with every call served (requests and streams opened); `idle`:
  // nothing in flight. Trims when idle and there was activity since the last trim; says whether it did.
  bool poll(long long activity, bool idle);
  long long trims() const { return trims_; }

 private:
  long long trimmed_at_ = 0;
  long long trims_ = 0;
};

}  // namespace mufric::server
