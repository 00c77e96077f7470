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

  // bytes 0: no limit. trim_after_bytes: once this many bytes were reserved since the last time
  // nothing was in flight, the process returns freed memory to the system when the last call ends.
  explicit MemoryBudget(std::size_t bytes, std::size_t trim_after_bytes = kTrimAfterBytes)
      : limit_(bytes), trim_after_(trim_after_bytes) {}

  // A reservation of `bytes`, or an empty one when it does not fit beside the calls in flight. A
  // call alone is always admitted, whatever its size: refusing it could never succeed later.
  Reservation try_reserve(std::size_t bytes);
  std::size_t in_use() const;
  std::size_t limit() const { return limit_; }
  long long trims() const { return trims_.load(); }

  static constexpr std::size_t kTrimAfterBytes = std::size_t{64} << 20;

 private:
  void release(std::size_t bytes);

  const std::size_t limit_;
  const std::size_t trim_after_;
  mutable std::mutex mutex_;
  std::size_t in_use_ = 0;
  std::size_t since_idle_ = 0;  // bytes reserved since in_use_ was last 0
  std::atomic<long long> trims_{0};
};

}  // namespace mufric::server
