#pragma once
// OpenBLAS thread control for callers that parallelise themselves or whose BLAS calls are too small
// to share (the sparse LU's supernodes): threads that spin in sched_yield cost more than they give.
namespace mufric {

// Limits OpenBLAS to one thread while the caller runs its own parallel loop; restores on exit.
class SingleThreadedBlas {
 public:
  SingleThreadedBlas();
  ~SingleThreadedBlas();
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;

 private:
  int previous_;
};

}  // namespace mufric
