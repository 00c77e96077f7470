// `mufric bench`: throughput and latency of a model through the client interface, so the same
// command measures a server (grpc://, grpcs://) and the in-process evaluator (file://).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "app/commands.hpp"
#include "client/friction_client.hpp"
#include "common/error.hpp"
#include "common/wording.hpp"

namespace mufric::app {
namespace {

// Points drawn uniformly in the model's box, one array per input, as a meso code holds them.
struct RandomBlock {
  std::vector<std::vector<double>> columns;
  client::Block block;

  RandomBlock(const InputSpace& inputs, size_t count, std::uint64_t seed) : columns(inputs.size()) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    block.points = count;
    for (size_t j = 0; j < inputs.size(); ++j) {
      for (size_t i = 0; i < count; ++i) columns[j].push_back(inputs[j].lo + unit(rng) * (inputs[j].hi - inputs[j].lo));
      if (const auto field = client::Block::field_for(inputs[j].name)) block.*field = columns[j].data();
    }
  }
};

struct Measurement {
  std::vector<double> latencies;  // seconds per call, all clients
  long long errors = 0;
  std::string first_error;
  double wall_seconds = 0.0;
};

Measurement measure(const std::string& uri, const client::Options& options, long long batch, int clients,
                    double seconds, const EvaluationRequest& what) {
  Measurement m;
  std::mutex mutex;
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      std::vector<double> local;
      long long errors = 0;
      std::string first_error;
      try {
        client::Options own = options;
        own.own_connection = true;  // N clients are N connections, as N meso-code processes would be
        const auto client = client::connect(uri, own);
        const RandomBlock points(client->describe().inputs, static_cast<size_t>(batch), 7 + static_cast<unsigned>(c));
        client->evaluate(points.block, what);  // warm-up: connection, caches
        while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < seconds ||
               local.size() < 5) {
          const auto t0 = std::chrono::steady_clock::now();
          try {
            client->evaluate(points.block, what);
          } catch (const Error& e) {
            if (errors++ == 0) first_error = e.what();
          }
          local.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
      } catch (const Error& e) {
        if (errors++ == 0) first_error = e.what();
      }
      std::lock_guard lock(mutex);
      m.latencies.insert(m.latencies.end(), local.begin(), local.end());
      m.errors += errors;
      if (m.first_error.empty()) m.first_error = first_error;
    });
  }
  for (auto& t : threads) t.join();
  m.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::sort(m.latencies.begin(), m.latencies.end());
  return m;
}

// Meso-trace replay: `points` contact points whose states drift by a random walk of 0.5 % of the
// box width per increment (reflected at the box walls), one evaluate() per increment.
Measurement replay(const std::string& uri, const client::Options& options, long long points, long long increments,
                   const EvaluationRequest& what) {
  constexpr double kDriftPerIncrement = 0.005;
  Measurement m;
  const auto client = client::connect(uri, options);
  const InputSpace inputs = client->describe().inputs;
  RandomBlock state(inputs, static_cast<size_t>(points), 11);
  std::mt19937_64 rng(12);
  std::normal_distribution<double> step(0.0, kDriftPerIncrement);
  const auto start = std::chrono::steady_clock::now();
  for (long long k = 0; k < increments; ++k) {
    for (size_t j = 0; j < inputs.size(); ++j) {
      const double width = inputs[j].hi - inputs[j].lo;
      for (double& x : state.columns[j]) {
        x += width * step(rng);
        if (x < inputs[j].lo) x = 2 * inputs[j].lo - x;
        if (x > inputs[j].hi) x = 2 * inputs[j].hi - x;
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    try {
      client->evaluate(state.block, what);
    } catch (const Error& e) {
      if (m.errors++ == 0) m.first_error = e.what();
    }
    m.latencies.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  m.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::sort(m.latencies.begin(), m.latencies.end());
  return m;
}

// A benchmark with failed calls measured something else than the model (errors answer fast, or
// time out), so its figures must not pass for a result in a script: exit code 2 (README), after the
// table, with how many failed and why the first did.
void refuse_failed_calls(long long failed, const std::string& first_error) {
  if (failed == 0) return;
  throw Error("bench: " + count_of(failed, "call", "calls") + " failed, the first: " + first_error);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  struct Options {
    std::string model;
    std::vector<long long> batches{1, 64, 1024, 16384};
    int clients = 1;
    double seconds = 1.0;
    bool with_std = false;
    bool patch_std = false;
    bool streaming = false;
    bool json = false;
    bool exact = false;
    std::string client_options;
    std::vector<long long> replay;  // points, increments
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("bench", "Throughput and latency of a model: in-process (file://) or a server (grpc://)");
  cmd->add_option("--model", o->model, "file:///path/model.h5 (or a path), a shipped model's name (dry_default), grpc://host:port/model")->required();
  cmd->add_option("--batch", o->batches, "Batch sizes (points per call)")->capture_default_str()->expected(1, 16)
      ->check(CLI::Range(1LL, 100'000'000LL));
  cmd->add_option("--clients", o->clients, "Concurrent clients, each with its own connection")
      ->capture_default_str()->check(CLI::Range(1, 1024));
  cmd->add_option("--seconds", o->seconds, "Measuring time per batch size")->capture_default_str()
      ->check(FiniteRange(0.01, 3600.0));
  cmd->add_flag("--std", o->with_std, "Also the standard deviation and a 95 % interval");
  cmd->add_flag("--patch-std", o->patch_std, "Also the patch scatter (a model trained on independent draws)");
  cmd->add_flag("--stream", o->streaming, "grpc://: send blocks over one EvaluateStream per client");
  cmd->add_flag("--json", o->json, "One JSON object per batch size instead of a table");
  cmd->add_flag("--exact", o->exact, "Ask for the exact model only (no certified fast evaluator)");
  cmd->add_option("--client-options", o->client_options,
                  "Client options as the C ABI takes them, e.g. \"chunk_points=1024, deadline=5\"");
  cmd->add_option("--replay", o->replay,
                  "Meso-trace replay instead of fixed batches: POINTS,INCREMENTS contact points drifting over "
                  "increments, one call per increment")
      ->delimiter(',')->expected(2)->check(CLI::Range(1LL, 1'000'000'000LL));
  cmd->callback([o] {
    EvaluationRequest what{
        .std = o->with_std, .ci_level = o->with_std ? 0.95 : 0.0, .gradient = false, .patch_std = o->patch_std};
    if (o->exact) what.mu_tolerance = what.std_relative_tolerance = 0.0;
    client::Options options = client::parse_options(o->client_options);
    options.streaming = options.streaming || o->streaming;
    options.isolate_file_parsing = true;  // a command-line tool: a corrupt file is an error, not a crash
    if (!o->replay.empty()) {
      const Measurement m = replay(o->model, options, o->replay[0], o->replay[1], what);
      const double p50 = m.latencies[m.latencies.size() / 2];
      const double p99 = m.latencies[std::min(m.latencies.size() - 1, m.latencies.size() * 99 / 100)];
      const double rate = static_cast<double>(o->replay[0] * std::max(0LL, o->replay[1] - m.errors)) / m.wall_seconds;  // answered
      if (o->json) {
        std::printf("{\"replay_points\": %lld, \"increments\": %lld, \"seconds\": %.4g, \"points_per_second\": %.6g, "
                    "\"p50_us\": %.4g, \"p99_us\": %.4g, \"errors\": %lld}\n",
                    o->replay[0], o->replay[1], m.wall_seconds, rate, 1e6 * p50, 1e6 * p99, m.errors);
      } else {
        std::printf("replay %lld points x %lld increments on %s: %.3g s, %.4g points/s, per increment p50 %.4g us, "
                    "p99 %.4g us, %lld errors\n",
                    o->replay[0], o->replay[1], o->model.c_str(), m.wall_seconds, rate, 1e6 * p50, 1e6 * p99, m.errors);
      }
      refuse_failed_calls(m.errors, m.first_error);
      return;
    }
    if (!o->json) {
      std::printf("%10s %10s %14s %12s %12s %8s   (%s, %s, %d client%s)\n", "batch", "calls", "points/s", "p50 [us]",
                  "p99 [us]", "errors", o->model.c_str(),
                  o->with_std ? (o->patch_std ? "mean+std+patch_std" : "mean+std") : (o->patch_std ? "mean+patch_std" : "mean only"),
                  o->clients,
                  o->clients == 1 ? "" : "s");
    }
    long long failed_calls = 0;
    std::string first_error;
    for (const long long batch : o->batches) {
      const Measurement m = measure(o->model, options, batch, o->clients, o->seconds, what);
      if (m.latencies.empty()) throw Error("bench: no call succeeded: " + m.first_error);
      failed_calls += m.errors;
      if (first_error.empty()) first_error = m.first_error;
      const double p50 = m.latencies[m.latencies.size() / 2];
      const double p99 = m.latencies[std::min(m.latencies.size() - 1, m.latencies.size() * 99 / 100)];
      // Answered points only: a failed call moved no points (it also makes the command exit 2).
      const double answered_calls = std::max(0.0, static_cast<double>(m.latencies.size()) - static_cast<double>(m.errors));
      const double points_per_second = static_cast<double>(batch) * answered_calls / m.wall_seconds;
      if (o->json) {
        std::printf("{\"batch\": %lld, \"clients\": %d, \"calls\": %zu, \"points_per_second\": %.6g, \"p50_us\": %.4g, "
                    "\"p99_us\": %.4g, \"errors\": %lld, \"std\": %s, \"patch_std\": %s}\n",
                    batch, o->clients, m.latencies.size(), points_per_second, 1e6 * p50, 1e6 * p99, m.errors,
                    o->with_std ? "true" : "false", o->patch_std ? "true" : "false");
      } else {
        std::printf("%10lld %10zu %14.4g %12.4g %12.4g %8lld\n", batch, m.latencies.size(), points_per_second, 1e6 * p50,
                    1e6 * p99, m.errors);
      }
    }
    refuse_failed_calls(failed_calls, first_error);
  });
}

}  // namespace mufric::app
