#pragma once
// OpenBLAS thread control for callers that parallelise themselves or whose BLAS calls are too small
// to share (the sparse LU's supernodes): threads that spin in sched_yield cost more than they give.
namespace mufric {

// Limits OpenBLAS to one thread while any guard is alive, in any thread; the last guard to go
// restores the count the first one found.
class SingleThreadedBlas {
 public:
  SingleThreadedBlas();
  ~SingleThreadedBlas();
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;
};

int blas_threads();  // OpenBLAS's current thread count

}  // namespace mufric
