#pragma once
// Parsing an untrusted file away from the process that will use it. The HDF5 library trusts the
// bytes it reads: one flipped length in a global heap makes it dereference wild pointers (SIGSEGV)
// or loop forever. A child process parses the file and, if that succeeds, writes what it accepted
// with mufric's own writer; the caller then reads only that rewritten copy, so a crash, a hang or an
// exhausted memory limit costs the child, never the caller, and the caller never parses the
// original bytes (which may also be changing under it, e.g. a file still being copied in).
#include <functional>
#include <string>

#include "common/error.hpp"

namespace mufric {

// The check could not be made (no process could be forked, or the child stalled on a lock it
// inherited): nothing is known about the file, so a caller that refuses it should try again later.
class CheckerUnavailable : public Error {
 public:
  using Error::Error;
};

struct IsolationLimits {
  double seconds = 60.0;                           // wall time before the child is killed
  unsigned long long memory_bytes = 8ULL << 30;    // the child's address-space limit (not under ASan)
};

// A rewritten copy in the temporary directory, removed when this goes out of scope.
class IsolatedCopy {
 public:
  explicit IsolatedCopy(std::string path) : path_(std::move(path)) {}
  ~IsolatedCopy();
  IsolatedCopy(IsolatedCopy&& other) noexcept : path_(std::move(other.path_)) { other.path_.clear(); }
  IsolatedCopy(const IsolatedCopy&) = delete;
  IsolatedCopy& operator=(const IsolatedCopy&) = delete;
  IsolatedCopy& operator=(IsolatedCopy&&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

using Rewrite = std::function<void(const std::string& original, const std::string& copy)>;

// Runs `rewrite(original, copy)` in a forked child; `rewrite` must parse `original` and write what it
// accepted to `copy`. Throws Error "<what> '<original>': <reason>" when the child throws (its message
// is passed on as it is), crashes (the signal is named), runs out of time or memory, or writes
// nothing. A child that sleeps without progress (a lock inherited locked at fork) is forked again,
// a few times at most; then, as when no child can be forked, CheckerUnavailable says so. Only for processes that may fork (the CLI, the server), not inside a meso code.
IsolatedCopy rewrite_in_child(const std::string& original, const std::string& what, const Rewrite& rewrite,
                              const IsolationLimits& limits = {});

}  // namespace mufric
