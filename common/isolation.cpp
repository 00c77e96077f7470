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

#include "common/error.hpp"

namespace mufric {
namespace {

// The longest message a child passes back; the rest is cut (messages name a file and a field).
constexpr size_t kMaxMessageBytes = 4096;

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

IsolatedCopy rewrite_in_child(const std::string& original, const std::string& what, const Rewrite& rewrite,
                              const IsolationLimits& limits) {
  const auto fail = [&](const std::string& reason) -> Error { return Error(what + " '" + original + "': " + reason); };
  IsolatedCopy copy(unique_copy_path());
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
    child_main(fds[1], original, copy.path(), rewrite, limits);
  }
  ::close(fds[1]);
  // Read the child's message until it closes the pipe (exits) or the time is up.
  std::string message;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limits.seconds);
  bool timed_out = false;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    char buffer[512];
    const ssize_t got = ::read(fds[0], buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;  // the child closed its end: it has exited
    message.append(buffer, static_cast<size_t>(got));
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) {
    throw fail("parsing it did not finish within " + std::to_string(static_cast<int>(limits.seconds)) +
               " s (a corrupt file can make the HDF5 library loop); refused");
  }
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    throw fail("parsing it crashed (signal " + std::to_string(signal) + ", " +
               ::strsignal(signal) + "): the file is corrupt; refused");
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    if (message.empty()) message = "parsing it failed (exit status " + std::to_string(WEXITSTATUS(status)) + ")";
    throw Error(message);  // the child's own message already names the file
  }
  if (!std::filesystem::exists(copy.path())) throw fail("the checking process wrote no copy");
  return copy;
}

}  // namespace mufric
