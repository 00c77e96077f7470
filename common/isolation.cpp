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

namespace mufric {
namespace {

// The longest message a child passes back; the rest is cut (messages name a file and a field).
constexpr size_t kMaxMessageBytes = 4096;

// fork() in a threaded process (the server's gRPC threads) copies every lock as it is: a child
// forked while another thread held one (libasan 8 does not lock its allocator around fork; a
// library's global mutex) waits for it forever. Parsing never sleeps: a child asleep without using
// CPU for this long is such a child, and a fresh fork almost surely finds the lock free.
constexpr double kStalledSeconds = 2.0;
constexpr int kForkAttempts = 3;
constexpr int kActivityCheckMs = 250;

#if defined(__SANITIZE_ADDRESS__)
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

// Whether the child sleeps (state S) and how much CPU it has used, from /proc/<pid>/stat
// (proc(5): state is the 3rd field, utime and stime the 14th and 15th).
struct ChildActivity {
  bool sleeping = false;
  unsigned long long cpu_ticks = 0;
};

std::optional<ChildActivity> child_activity(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(in, line)) return std::nullopt;
  const auto name_end = line.rfind(')');  // the command name may hold spaces and parentheses
  if (name_end == std::string::npos) return std::nullopt;
  std::istringstream fields(line.substr(name_end + 1));
  char state = 0;
  fields >> state;
  std::string skipped;
  for (int field = 4; field <= 13; ++field) fields >> skipped;
  unsigned long long user = 0, system = 0;
  if (!(fields >> user >> system)) return std::nullopt;
  return ChildActivity{state == 'S', user + system};
}

// One child: fork, run the rewrite, read its message until it exits, is out of time or stalls.
ChildOutcome run_child(const std::string& original, const std::string& copy_path, const Rewrite& rewrite,
                       const IsolationLimits& limits, const std::function<Error(const std::string&)>& fail) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw fail(std::string("cannot create a pipe to check it: ") + std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw fail(std::string("cannot fork a process to check it: ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child_main(fds[1], original, copy_path, rewrite, limits);
  }
  ::close(fds[1]);
  ChildOutcome outcome;
  const auto now = [] { return std::chrono::steady_clock::now(); };
  const auto deadline = now() + std::chrono::duration<double>(limits.seconds);
  auto last_progress = now();
  unsigned long long last_cpu_ticks = 0;
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
      if (activity && (!activity->sleeping || activity->cpu_ticks != last_cpu_ticks)) last_progress = now();
      if (activity) last_cpu_ticks = activity->cpu_ticks;
      if (now() - last_progress > std::chrono::duration<double>(kStalledSeconds)) {
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
  const auto fail = [&](const std::string& reason) -> Error { return Error(what + " '" + original + "': " + reason); };
  IsolatedCopy copy(unique_copy_path());
  ChildOutcome outcome;
  for (int attempt = 1;; ++attempt) {
    outcome = run_child(original, copy.path(), rewrite, limits, fail);
    if (outcome.end != ChildEnd::stalled) break;
    if (attempt == kForkAttempts) {
      throw fail("the checking process slept without progress in " + std::to_string(kForkAttempts) +
                 " attempts (a lock held by another thread when it was forked); refused for now");
    }
  }
  if (outcome.end == ChildEnd::timed_out) {
    throw fail("parsing it did not finish within " + std::to_string(static_cast<int>(limits.seconds)) +
               " s (a corrupt file can make the HDF5 library loop); refused");
  }
  const int status = outcome.status;
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    throw fail("parsing it crashed (signal " + std::to_string(signal) + ", " +
               ::strsignal(signal) + "): the file is corrupt; refused");
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string message = outcome.message;
    if (message.empty()) message = "parsing it failed (exit status " + std::to_string(WEXITSTATUS(status)) + ")";
    throw Error(message);  // the child's own message already names the file
  }
  if (!std::filesystem::exists(copy.path())) throw fail("the checking process wrote no copy");
  return copy;
}

}  // namespace mufric
