#include "common/isolation.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "common/error.hpp"
#include "common/sanitizers.hpp"

namespace mufric {
namespace {

// The longest message a child passes back; the rest is cut (messages name a file and a field).
constexpr size_t kMaxMessageBytes = 4096;

// fork() in a threaded process (the server's gRPC threads) copies every lock as it is: a child
// forked while another thread held one (libasan 8 does not lock its allocator around fork; a
// library's global mutex) waits for it forever, asleep or spinning. Parsing never does either: a
// child that makes no progress (touched_anything, computed_in_user_space) for this long is such a
// child, and a fresh fork almost surely finds the lock free.
constexpr double kStalledSeconds = 2.0;
constexpr int kForkAttempts = 3;
constexpr int kActivityCheckMs = 250;

#if MUFRIC_ADDRESS_SANITIZER
constexpr bool kAddressSpaceLimitAllowed = false;  // ASan reserves terabytes of shadow address space
#else
constexpr bool kAddressSpaceLimitAllowed = true;
#endif

std::string unique_copy_path() {
  static std::atomic<unsigned> counter{0};
  return (std::filesystem::temp_directory_path() /
          ("mufric-isolated-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".h5"))
      .string();
}

[[noreturn]] void child_main(int fd, const std::string& original, const std::string& copy, const Rewrite& rewrite,
                             const IsolationLimits& limits) {
  // What a dying parse prints (glibc's "malloc(): corrupted ...", a sanitizer's report) is not the
  // caller's output: its one-line error says what happened.
  if (const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC); null >= 0) {
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    ::close(null);
  }
  if (kAddressSpaceLimitAllowed && limits.memory_bytes > 0) {
    const rlimit memory{limits.memory_bytes, limits.memory_bytes};
    setrlimit(RLIMIT_AS, &memory);
  }
  std::string message;
  int code = 0;
  try {
    rewrite(original, copy);
  } catch (const std::bad_alloc&) {
    message = "needs more memory than the limit of " + std::to_string(limits.memory_bytes >> 20) +
              " MiB while parsing (corrupt sizes?)";
    code = 1;
  } catch (const std::exception& e) {
    message = e.what();
    code = 1;
  } catch (...) {
    message = "unknown exception while parsing";
    code = 1;
  }
  if (message.size() > kMaxMessageBytes) message.resize(kMaxMessageBytes);
  for (size_t written = 0; written < message.size();) {
    const ssize_t w = ::write(fd, message.data() + written, message.size() - written);
    if (w <= 0) break;
    written += static_cast<size_t>(w);
  }
  ::_exit(code);  // no destructors, no atexit handlers of the parent's libraries
}

}  // namespace

IsolatedCopy::~IsolatedCopy() {
  if (path_.empty()) return;
  std::error_code ignored;
  std::filesystem::remove(path_, ignored);
}

namespace {

enum class ChildEnd { exited, timed_out, stalled };

struct ChildOutcome {
  ChildEnd end = ChildEnd::exited;
  int status = 0;       // waitpid's status when it exited
  std::string message;  // what the child wrote to the pipe
};

// What the child has done, from /proc/<pid>/stat (proc(5): minflt is the 10th field,
// utime and stime the 14th and 15th) and /proc/<pid>/io (bytes read and written by any means).
struct ChildActivity {
  unsigned long long minor_faults = 0;
  unsigned long long user_ticks = 0;
  unsigned long long system_ticks = 0;
  unsigned long long io_bytes = 0;  // 0 where /proc/<pid>/io is not readable
};

std::optional<ChildActivity> child_activity(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(in, line)) return std::nullopt;
  const auto name_end = line.rfind(')');  // the command name may hold spaces and parentheses
  if (name_end == std::string::npos) return std::nullopt;
  std::istringstream fields(line.substr(name_end + 1));
  ChildActivity activity;
  std::string skipped;
  for (int field = 3; field <= 9; ++field) fields >> skipped;
  fields >> activity.minor_faults;
  for (int field = 11; field <= 13; ++field) fields >> skipped;
  if (!(fields >> activity.user_ticks >> activity.system_ticks)) return std::nullopt;
  std::ifstream io("/proc/" + std::to_string(pid) + "/io");
  std::string key;
  unsigned long long value = 0;
  while (io >> key >> value) {
    if (key == "rchar:" || key == "wchar:") activity.io_bytes += value;
  }
  return activity;
}

// Parsing reads, writes, touches new memory or computes in user space (a large covariance is
// refactorised without I/O). A child stuck on an inherited lock does none of these: a sleeping lock
// leaves it asleep without CPU, a spinning one (libasan's StaticSpinMutex: sched_yield in a loop)
// spends its CPU mostly in the kernel. The split of CPU time is judged over the whole stall window:
// the clock ticks of a child that yields on a busy machine are too few to judge a single look by.
bool touched_anything(const ChildActivity& before, const ChildActivity& now) {
  return now.io_bytes != before.io_bytes || now.minor_faults != before.minor_faults;
}

bool computed_in_user_space(const ChildActivity& before, const ChildActivity& now) {
  return now.user_ticks - before.user_ticks > now.system_ticks - before.system_ticks;
}

// One child: fork, run the rewrite, read its message until it exits, is out of time or stalls.
ChildOutcome run_child(const std::string& original, const std::string& copy_path, const Rewrite& rewrite,
                       const IsolationLimits& limits, const std::function<std::string(const std::string&)>& fail) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    throw CheckerUnavailable(fail(std::string("cannot create a pipe to check it: ") + std::strerror(errno) +
                                  " (not the file's fault: try again)"));
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw CheckerUnavailable(fail(std::string("cannot fork a process to check it: ") + std::strerror(errno) +
                                  " (not the file's fault: try again)"));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child_main(fds[1], original, copy_path, rewrite, limits);
  }
  ::close(fds[1]);
  ChildOutcome outcome;
  const auto now = [] { return std::chrono::steady_clock::now(); };
  const auto deadline = now() + std::chrono::duration<double>(limits.seconds);
  auto window_start = now();
  std::optional<ChildActivity> window_activity;  // the child's counters when the window started
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now());
    if (left.count() <= 0) {
      outcome.end = ChildEnd::timed_out;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), kActivityCheckMs)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) {
      const auto activity = child_activity(pid);
      if (!activity) continue;
      const bool window_over = now() - window_start > std::chrono::duration<double>(kStalledSeconds);
      if (!window_activity || touched_anything(*window_activity, *activity) ||
          (window_over && computed_in_user_space(*window_activity, *activity))) {
        window_start = now();
        window_activity = activity;
      } else if (window_over) {
        outcome.end = ChildEnd::stalled;
        break;
      }
      continue;
    }
    char buffer[512];
    const ssize_t got = ::read(fds[0], buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;  // the child closed its end: it has exited
    outcome.message.append(buffer, static_cast<size_t>(got));
  }
  ::close(fds[0]);
  if (outcome.end != ChildEnd::exited) ::kill(pid, SIGKILL);
  while (::waitpid(pid, &outcome.status, 0) < 0 && errno == EINTR) {
  }
  return outcome;
}

}  // namespace

IsolatedCopy rewrite_in_child(const std::string& original, const std::string& what, const Rewrite& rewrite,
                              const IsolationLimits& limits) {
  const auto fail = [&](const std::string& reason) { return what + " '" + original + "': " + reason; };
  IsolatedCopy copy(unique_copy_path());
  ChildOutcome outcome;
  for (int attempt = 1;; ++attempt) {
    outcome = run_child(original, copy.path(), rewrite, limits, fail);
    if (outcome.end != ChildEnd::stalled) break;
    if (attempt == kForkAttempts) {
      throw CheckerUnavailable(fail("the checking process waited without progress in " + std::to_string(kForkAttempts) +
                                    " attempts: it was forked while another thread of this process held a lock it "
                                    "needs (not the file's fault; not checked, try again)"));
    }
  }
  if (outcome.end == ChildEnd::timed_out) {
    throw Error(fail("parsing it did not finish within " + std::to_string(static_cast<int>(limits.seconds)) +
               " s (a corrupt file can make the HDF5 library loop); refused"));
  }
  const int status = outcome.status;
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    throw Error(fail("parsing it crashed (signal " + std::to_string(signal) + ", " + ::strsignal(signal) +
                     "): the file is corrupt; refused"));
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string message = outcome.message;
    if (message.empty()) message = "parsing it failed (exit status " + std::to_string(WEXITSTATUS(status)) + ")";
    throw Error(message);  // the child's own message already names the file
  }
  if (!std::filesystem::exists(copy.path())) throw Error(fail("the checking process wrote no copy"));
  return copy;
}

}  // namespace mufric
