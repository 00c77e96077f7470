// common/blas_threads: OpenBLAS's one process-wide thread count under guards held by several
// threads at once (the draws of a μ measurement).
#include <gtest/gtest.h>

#include <future>
#include <optional>
#include <thread>

#include "common/blas_threads.hpp"

namespace mufric {
namespace {

// Guards that do not end in the order they began: the first to end must not hand the threads back
// while the other still holds one (it did: a draw finishing first gave the other draw its BLAS
// threads in the middle of its run, and the last digits of μ changed from run to run).
TEST(BlasThreads, OneThreadUntilTheLastGuardEnds) {
  const int before = blas_threads();
  if (before == 1) GTEST_SKIP() << "OpenBLAS runs one thread here already: nothing to hand back";
  std::optional<SingleThreadedBlas> first;
  first.emplace();
  EXPECT_EQ(blas_threads(), 1);
  std::promise<void> second_held, first_ended;
  std::thread other([&] {
    const SingleThreadedBlas second;
    second_held.set_value();
    first_ended.get_future().wait();
    EXPECT_EQ(blas_threads(), 1) << "the first guard to end gave the threads back";
  });
  second_held.get_future().wait();
  first.reset();
  first_ended.set_value();
  other.join();
  EXPECT_EQ(blas_threads(), before);
}

}  // namespace
}  // namespace mufric
