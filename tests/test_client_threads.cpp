// One client handle shared by the threads of a meso code, through the C ABI (in-process and over
// gRPC) and the C++ client's stream: every thread gets exactly the answers a lone caller gets. Run
// in the Release build and under ThreadSanitizer (deploy/test.sh, build-tsan), the server a process of its own. Blocks stay below the
// GP's parallel threshold so that no OpenMP team runs: libgomp is not instrumented for TSan.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "client/friction_client.hpp"
#include "client/mufric.h"
#include "gp_test_data.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric {
namespace {

namespace fs = std::filesystem;

constexpr int kThreads = 4;
// Under ThreadSanitizer on a busy 2-core node the first connection can take longer than the default
// retry schedule (0.75 s in all): a fresh clone's CI failed once with UNAVAILABLE at open.
constexpr const char* kPatientRetries = "retries=8, backoff=0.1";
constexpr int kCallsPerThread = 40;

// Blocks of the sizes a meso code's sub-domains send, each with its own points.
struct Block {
  std::vector<double> p, v, t;
};

std::vector<Block> blocks_for_thread(int thread) {
  std::vector<Block> blocks;
  for (int call = 0; call < kCallsPerThread; ++call) {
    const auto size = static_cast<Eigen::Index>(1 + (37 * call + 11 * thread) % 200);
    const TrainingSet s = test::smooth_training_set(size, static_cast<unsigned>(1000 * thread + call));
    Block b;
    for (Eigen::Index i = 0; i < size; ++i) {
      b.p.push_back(s.x(i, 0));
      b.v.push_back(s.x(i, 1));
      b.t.push_back(s.x(i, 2));
    }
    blocks.push_back(std::move(b));
  }
  return blocks;
}

struct Outputs {
  std::vector<double> mu, lo, hi;
  bool operator==(const Outputs&) const = default;
};

Outputs evaluate_c(mufric_client* client, const Block& b, double ci_level) {
  Outputs o{std::vector<double>(b.p.size()), std::vector<double>(b.p.size()), std::vector<double>(b.p.size())};
  const bool interval = ci_level > 0.0;
  if (mufric_evaluate(client, b.p.size(), b.p.data(), b.v.data(), b.t.data(), nullptr, ci_level, o.mu.data(), nullptr,
                      interval ? o.lo.data() : nullptr, interval ? o.hi.data() : nullptr, nullptr) != MUFRIC_OK) {
    ADD_FAILURE() << mufric_last_error();
  }
  return o;
}

// References from one thread first, then every thread at once on the same handle: equal to the bit.
void expect_threads_get_lone_answers(mufric_client* client) {
  std::vector<std::vector<Block>> blocks;
  std::vector<std::vector<Outputs>> expected(kThreads);
  for (int t = 0; t < kThreads; ++t) {
    blocks.push_back(blocks_for_thread(t));
    for (int c = 0; c < kCallsPerThread; ++c) expected[t].push_back(evaluate_c(client, blocks[t][c], c % 2 ? 0.95 : 0.0));
  }
  std::atomic<int> mismatches{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int c = 0; c < kCallsPerThread; ++c) {
        if (!(evaluate_c(client, blocks[t][c], c % 2 ? 0.95 : 0.0) == expected[t][c])) ++mismatches;
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(mismatches.load(), 0);
}

class SharedHandle : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("mufric_threads_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    save_model((dir_ / "gp.h5").string(), test::fixed_hyper_gp(200, 3, 2.0, {0.6, 0.7, 0.8}, 1e-4));
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `mufric serve` in a process of its own (MUFRIC_SERVE_BINARY): under ThreadSanitizer only the
  // client side is in this process, and the server's model loader may fork its parser freely.
  struct ServerProcess {
    explicit ServerProcess(const fs::path& directory) {
      const char* binary = std::getenv("MUFRIC_SERVE_BINARY");
      if (binary == nullptr) throw std::runtime_error("MUFRIC_SERVE_BINARY (the mufric executable) is not set");
      const std::string ready = (directory / "ready").string();
      const std::string models = directory.string();
      std::vector<std::string> arguments{binary, "serve", "--models", models, "--listen", "127.0.0.1:0",
                                         "--ready-file", ready};
      std::vector<char*> argv;
      for (auto& a : arguments) argv.push_back(a.data());
      argv.push_back(nullptr);
      if (posix_spawn(&pid, binary, nullptr, nullptr, argv.data(), environ) != 0) {
        throw std::runtime_error(std::string("cannot start ") + binary);
      }
      for (int waited_ms = 0; waited_ms < 30000; waited_ms += 20) {
        std::ifstream file(ready);
        if (std::getline(file, address) && !address.empty()) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      stop();
      throw std::runtime_error("mufric serve did not write " + ready + " within 30 s");
    }
    ~ServerProcess() { stop(); }
    void stop() {
      if (pid <= 0) return;
      ::kill(pid, SIGTERM);
      int status = 0;
      ::waitpid(pid, &status, 0);
      pid = 0;
    }
    ServerProcess(const ServerProcess&) = delete;
    ServerProcess& operator=(const ServerProcess&) = delete;
    pid_t pid = 0;
    std::string address;  // host:port
  };

  fs::path dir_;
};

TEST_F(SharedHandle, CAbiInProcessFromManyThreadsAtOnce) {
  mufric_client* client = nullptr;
  ASSERT_EQ(mufric_open(("file://" + (dir_ / "gp.h5").string()).c_str(), &client), MUFRIC_OK) << mufric_last_error();
  expect_threads_get_lone_answers(client);
  mufric_close(client);
}

TEST_F(SharedHandle, CAbiOverGrpcFromManyThreadsAtOnce) {
  const ServerProcess server(dir_);
  mufric_client* client = nullptr;
  const std::string uri = "grpc://" + server.address + "/gp";
  ASSERT_EQ(mufric_open_with_options(uri.c_str(), kPatientRetries, &client), MUFRIC_OK) << mufric_last_error();
  expect_threads_get_lone_answers(client);
  mufric_close(client);
}

// The stream of one handle carries one request at a time: threads sharing it take turns, and each
// gets the answer to its own block (not another thread's).
TEST_F(SharedHandle, CppStreamSharedByManyThreads) {
  const ServerProcess server(dir_);
  const std::string uri = "grpc://" + server.address + "/gp";
  const client::Options patient = client::parse_options(kPatientRetries);
  const auto lone = client::connect(uri, patient);  // unary calls of the same server: the same binary's rounding
  client::Options one_stream = patient;
  one_stream.streaming = true;
  const auto streaming = client::connect(uri, one_stream);
  std::atomic<int> mismatches{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (const Block& b : blocks_for_thread(t)) {
        const client::Block block{b.p.size(), b.p.data(), b.v.data(), b.t.data(), nullptr};
        const client::Answer got = streaming->evaluate(block, {.ci_level = 0.95});
        const client::Answer want = lone->evaluate(block, {.ci_level = 0.95});
        if (got.mu != want.mu || got.hi != want.hi) ++mismatches;
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(mismatches.load(), 0);
}

}  // namespace
}  // namespace mufric
