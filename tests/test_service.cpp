// Server and C++ client end to end on loopback: same answers as in-process, per-point statuses,
// every malformed-request case, hot reload under load with zero failed requests, reconnection
// after a server restart, and the standard health service.
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <condition_variable>
#include <fstream>
#include <iterator>
#include <mutex>
#include <random>
#include <sstream>
#include <cmath>
#include <filesystem>
#include <limits>
#include <thread>

#include <nlohmann/json.hpp>

#include "client/friction_client.hpp"
#include "client/mufric.h"
#include "common/csv_table.hpp"
#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "corrupt_files.hpp"
#include "gp_test_data.hpp"
#include "proto/wire_codec.hpp"
#include "server/friction_service.hpp"
#include "server/memory_budget.hpp"
#include "server/server.hpp"
#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/laws/empirical_laws.hpp"
#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/models/model_file.hpp"
#include "surrogate/gp/stochastic_kriging.hpp"

namespace mufric {
namespace {

namespace fs = std::filesystem;

// A FrictionService on 127.0.0.1 with its own model directory.
class LoopbackServer {
 public:
  explicit LoopbackServer(const fs::path& directory, int port = 0, server::ServiceLimits limits = {},
                          std::shared_ptr<grpc::ServerCredentials> credentials = grpc::InsecureServerCredentials())
      : registry_(directory, [](const std::string&, const std::string&) {}), service_(registry_, std::move(limits)) {
    registry_.refresh();
    grpc::EnableDefaultHealthCheckService(true);
    grpc::ServerBuilder builder;
    builder.AddListeningPort("127.0.0.1:" + std::to_string(port), credentials, &port_);
    builder.RegisterService(&service_);
    server_ = builder.BuildAndStart();
  }
  ~LoopbackServer() { server_->Shutdown(); }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  int port() const { return port_; }
  server::ModelRegistry& registry() { return registry_; }
  const server::FrictionService& service() const { return service_; }

 private:
  server::ModelRegistry registry_;
  server::FrictionService service_;
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
};

class Service : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("mufric_service_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    save_model((dir_ / "gp.h5").string(), test::fixed_hyper_gp(200, 3, 2.0, {0.6, 0.7, 0.8}, 1e-4));
    save_model((dir_ / "coulomb.h5").string(), CoulombLaw(0.3));
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

struct Points {
  std::vector<double> p, v, t;
  client::Block block() const { return {p.size(), p.data(), v.data(), t.data(), nullptr}; }
};

Points random_points(size_t n) {
  const TrainingSet s = test::smooth_training_set(static_cast<Eigen::Index>(n), 21);
  Points pts;
  for (Eigen::Index i = 0; i < s.x.rows(); ++i) {
    pts.p.push_back(s.x(i, 0));
    pts.v.push_back(s.x(i, 1));
    pts.t.push_back(s.x(i, 2));
  }
  return pts;
}

TEST_F(Service, GrpcAnswersEqualInProcessAnswersAcrossChunks) {
  LoopbackServer server(dir_);
  client::Options options;
  // 1000 points → 4 calls. 330 would leave a last call of 10 points, which the GP answers row by
  // row where in-process they fall in a 104-query block; the client cuts at a multiple of the GP's
  // query block (256 here) so that σ keeps its bits.
  options.chunk_points = 330;
  const auto remote = client::connect("grpc://" + server.address() + "/gp", options);
  const auto local = client::connect("file://" + (dir_ / "gp.h5").string());
  const Points pts = random_points(1000);
  const EvaluationRequest what{.std = true, .ci_level = 0.95, .gradient = true};
  const client::Answer a = remote->evaluate(pts.block(), what), b = local->evaluate(pts.block(), what);
  ASSERT_EQ(a.mu.size(), 1000u);
  EXPECT_EQ(a.mu, b.mu);
  EXPECT_EQ(a.std, b.std);
  EXPECT_EQ(a.lo, b.lo);
  EXPECT_EQ(a.hi, b.hi);
  EXPECT_EQ(a.gradient, b.gradient);
  EXPECT_EQ(a.gradient_inputs, (std::vector<std::string>{"contact_pressure", "sliding_velocity", "temperature"}));
  EXPECT_EQ(a.model, "gp");
  EXPECT_EQ(a.version.size(), 16u);
  EXPECT_EQ(remote->describe().inputs.size(), 3u);
}

// The points without an answer are told about in the same words by both transports: the first one
// and why, numbered in the caller's block even when the client split it into several calls, and the
// count of the others; range-clipped points are counted alike; fill=V replaces NaN in every output.
TEST_F(Service, GrpcAndInProcessTellTheSameMessageAndCounts) {
  LoopbackServer server(dir_);
  client::Options options = client::parse_options("chunk_points=256, fill=-1");  // 1000 points → 4 calls
  const auto remote = client::connect("grpc://" + server.address() + "/gp", options);
  const auto local = client::connect("file://" + (dir_ / "gp.h5").string(), options);
  Points pts = random_points(1000);
  pts.p[300] = 5000e6;  // above the box, in the block's second call
  pts.t[700] = -10.0;   // invalid, in the third
  pts.v[999] = 1e-4;    // below the box, in the last
  EvaluationRequest refuse{.std = true, .ci_level = 0.95, .gradient = true};
  refuse.extrapolation = Extrapolation::refuse;
  const client::Answer a = remote->evaluate(pts.block(), refuse), b = local->evaluate(pts.block(), refuse);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.message.rfind("point 300 OUT_OF_BOX: contact_pressure: 5000MPa is above the box", 0), 0u) << a.message;
  EXPECT_NE(a.message.find("(and 2 more points without an answer)"), std::string::npos) << a.message;
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.status[700], PointStatus::invalid_input);
  for (const client::Answer* answer : {&a, &b}) {
    for (const size_t i : {300u, 700u, 999u}) {
      EXPECT_EQ(answer->mu[i], -1.0);
      EXPECT_EQ(answer->std[i], -1.0);
      EXPECT_EQ(answer->lo[i], -1.0);
      EXPECT_EQ(answer->hi[i], -1.0);
      EXPECT_EQ(answer->gradient[3 * i], -1.0);
    }
  }
  EXPECT_EQ(a.mu, b.mu);
  EXPECT_EQ(a.gradient, b.gradient);

  // Alone in a call of its own, the same point is point 0; a block of answered points says nothing.
  Points one = random_points(1);
  one.p[0] = 5000e6;
  EXPECT_EQ(remote->evaluate(one.block(), refuse).message, local->evaluate(one.block(), refuse).message);
  EXPECT_EQ(remote->evaluate(one.block(), refuse).message.rfind("point 0 OUT_OF_BOX", 0), 0u);
  EXPECT_EQ(remote->evaluate(random_points(10).block(), refuse).message, "");
  EXPECT_EQ(local->evaluate(random_points(10).block(), refuse).message, "");

  // A block answered but partly outside the box says so, in the same words, with how it was answered
  // (issue 72: the reply's message was empty for EXTRAPOLATED points); points without an answer come first.
  Points cold = random_points(600);
  cold.t[400] = 200.0;  // below the box, in the second call
  cold.t[500] = 150.0;
  const client::Answer c1 = remote->evaluate(cold.block(), {}), c2 = local->evaluate(cold.block(), {});
  EXPECT_EQ(c1.message, c2.message);
  EXPECT_EQ(c1.message.rfind("point 400 EXTRAPOLATED: temperature: ", 0), 0u) << c1.message;
  EXPECT_NE(c1.message.find("answered at temperature = "), std::string::npos) << c1.message;
  EXPECT_NE(c1.message.find("(clamp) (and 1 more point outside the box)"), std::string::npos) << c1.message;
  cold.p[550] = -5.0;  // invalid: its message wins
  EXPECT_EQ(remote->evaluate(cold.block(), {}).message.rfind("point 550 INVALID_INPUT", 0), 0u);
  EXPECT_EQ(local->evaluate(cold.block(), {}).message.rfind("point 550 INVALID_INPUT", 0), 0u);

  // The same GP declaring μ ≤ its median over these points: about half of them are clipped.
  const Points inside = random_points(600);
  std::vector<double> mu = local->evaluate(inside.block(), {}).mu;
  std::nth_element(mu.begin(), mu.begin() + 300, mu.end());
  {
    auto narrow = std::unique_ptr<FrictionModel>(load_model((dir_ / "gp.h5").string()));
    narrow->set_mu_range(0.0, mu[300]);
    save_model((dir_ / "narrow.h5").string(), *narrow);
  }
  server.registry().refresh();
  const EvaluationRequest interval{.ci_level = 0.95};
  const long long clipped_remote =
      client::connect("grpc://" + server.address() + "/narrow", options)->evaluate(inside.block(), interval).range_clipped;
  EXPECT_EQ(clipped_remote,
            client::connect("file://" + (dir_ / "narrow.h5").string())->evaluate(inside.block(), interval).range_clipped);
  EXPECT_GE(clipped_remote, 300);
}

// --log-uncertain: exactly the queried points whose 95 % interval is wider than the threshold land
// in DIR/<model>.csv, in SI with a unit header that the dataset tools read back; a caller that
// asked for μ only still gets μ only; a law (no uncertainty) logs nothing.
TEST_F(Service, UncertainQueriesAreLoggedForActiveLearning) {
  const Points pts = random_points(400);
  const auto local = client::connect("file://" + (dir_ / "gp.h5").string());
  const client::Answer reference = local->evaluate(pts.block(), {.std = true});
  std::vector<double> widths;
  for (const double s : reference.std) widths.push_back(2.0 * 1.959963984540054 * s);
  std::vector<double> sorted = widths;
  std::nth_element(sorted.begin(), sorted.begin() + 300, sorted.end());
  const double threshold = sorted[300];  // about a quarter of the points are wider
  UncertainQueryLog log((dir_ / "uncertain").string(), threshold, 1000);
  server::ServiceLimits limits;
  limits.evaluation_threads = 2;
  limits.uncertain_log = &log;
  LoopbackServer server(dir_, 0, limits);
  const auto remote = client::connect("grpc://" + server.address() + "/gp");
  const client::Answer a = remote->evaluate(pts.block(), {});
  EXPECT_TRUE(a.std.empty());
  EXPECT_EQ(a.mu, reference.mu);
  client::connect("grpc://" + server.address() + "/coulomb")->evaluate(pts.block(), {});
  EXPECT_FALSE(fs::exists(dir_ / "uncertain" / "coulomb.csv"));

  const CsvTable table = read_csv_table((dir_ / "uncertain" / "gp.csv").string());
  const auto p = table.si_column("contact_pressure"), v = table.si_column("sliding_velocity"),
             t = table.si_column("temperature");
  std::vector<size_t> expected;
  for (size_t i = 0; i < widths.size(); ++i) {
    if (widths[i] > threshold) expected.push_back(i);
  }
  ASSERT_EQ(p.size(), expected.size());
  EXPECT_GT(expected.size(), 50u);
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(p[k], pts.p[expected[k]]);
    EXPECT_EQ(v[k], pts.v[expected[k]]);
    EXPECT_EQ(t[k], pts.t[expected[k]]);
  }
  EXPECT_EQ(log.rows("gp"), static_cast<long long>(expected.size()));
}

// A meso code evaluating in-process logs for the learner without a server (client option
// log_uncertain=DIR, issue 69): the same block gives the server's log byte for byte (rows and the
// outside counts), every log_every-th call is logged, a caller asking μ only still gets μ only, and
// over gRPC the option is refused naming where the log belongs.
TEST_F(Service, AModelEvaluatedInProcessLogsItsQueriesAsTheServerDoes) {
  Points pts = random_points(200);
  for (size_t i = 0; i < pts.t.size(); i += 4) pts.t[i] = 200.0;  // a quarter below the box (cold contact)
  const double threshold = 0.01;
  {
    UncertainQueryLog log((dir_ / "served_log").string(), threshold, 1000);
    server::ServiceLimits limits;
    limits.uncertain_log = &log;
    LoopbackServer server(dir_, 0, limits);
    client::connect("grpc://" + server.address() + "/gp")->evaluate(pts.block(), {});
  }
  const fs::path in_process = dir_ / "in_process_log";
  client::Options options = client::parse_options("log_uncertain=" + in_process.string() + ", uncertain_width=0.01");
  {
    const auto local = client::connect("file://" + (dir_ / "gp.h5").string(), options);
    const client::Answer a = local->evaluate(pts.block(), {});
    EXPECT_TRUE(a.std.empty());
  }
  const auto text = [](const fs::path& file) {
    std::ifstream in(file);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  ASSERT_TRUE(fs::exists(in_process / "gp.csv"));
  EXPECT_EQ(text(in_process / "gp.csv"), text(dir_ / "served_log" / "gp.csv"));
  EXPECT_EQ(text(in_process / "gp.outside.json"), text(dir_ / "served_log" / "gp.outside.json"));
  EXPECT_GE(read_csv_table((in_process / "gp.csv").string()).si_column("temperature").size(), 50u);

  // every third call: calls 0 and 3 of five land, each the whole block's out-of-box rows
  const fs::path thinned = dir_ / "thinned_log";
  options = client::parse_options("log_uncertain=" + thinned.string() + ", uncertain_width=1e6, log_every=3");
  {
    const auto local = client::connect("file://" + (dir_ / "gp.h5").string(), options);
    for (int call = 0; call < 5; ++call) local->evaluate(pts.block(), {});
  }
  EXPECT_EQ(read_csv_table((thinned / "gp.csv").string()).si_column("temperature").size(), 2 * 50u);
  try {
    client::connect("grpc://127.0.0.1:1/gp", options);
    ADD_FAILURE() << "log_uncertain over gRPC was accepted";
  } catch (const client::InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("serve --log-uncertain"), std::string::npos) << e.what();
  }
}

// Out-of-box queries are logged whatever their width (under the clamp default their std is the
// box face's, narrow), and counted per input and side with the farthest value seen: the counts
// against a brute-force count of the same points, and they go on after the row cap.
TEST_F(Service, OutOfBoxQueriesAreLoggedAndCountedPerInputAndSide) {
  Points pts = random_points(300);
  const InputSpace box = default_friction_box();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double>* columns[] = {&pts.p, &pts.v, &pts.t};
  for (size_t i = 0; i < pts.p.size(); i += 3) {  // every third point: one input pushed out, side by turn
    const size_t j = (i / 3) % 3;
    const double span = box[j].hi - box[j].lo;
    (*columns[j])[i] = (i / 9) % 2 ? box[j].hi + u(rng) * span : std::max(box[j].lo - u(rng) * span, 0.5 * box[j].lo);
  }
  std::array<long long, 3> below{}, above{};
  std::array<double, 3> lowest{}, highest{};
  lowest.fill(std::numeric_limits<double>::infinity());
  highest.fill(-std::numeric_limits<double>::infinity());
  long long outside = 0;
  for (size_t i = 0; i < pts.p.size(); ++i) {
    bool any = false;
    for (size_t j = 0; j < 3; ++j) {
      const double value = (*columns[j])[i];
      if (value < box[j].lo) ++below[j], lowest[j] = std::min(lowest[j], value), any = true;
      if (value > box[j].hi) ++above[j], highest[j] = std::max(highest[j], value), any = true;
    }
    outside += any;
  }
  ASSERT_GT(outside, 90);
  const long long max_rows = 60;
  const fs::path dir = dir_ / "outside";
  {
    UncertainQueryLog log(dir.string(), 1e6, max_rows);  // no interval is that wide: only outside points
    server::ServiceLimits limits;
    limits.uncertain_log = &log;
    LoopbackServer server(dir_, 0, limits);
    const auto remote = client::connect("grpc://" + server.address() + "/gp");
    const client::Answer a = remote->evaluate(pts.block(), {});  // the clamp default: every point answered
    for (const double mu : a.mu) EXPECT_TRUE(std::isfinite(mu));
    const OutsideSummary s = log.outside("gp");
    EXPECT_EQ(s.queries, static_cast<long long>(pts.p.size()));
    EXPECT_EQ(s.outside_queries, outside);
    for (size_t j = 0; j < 3; ++j) {
      EXPECT_EQ(s.inputs[j].below, below[j]) << box[j].name;
      EXPECT_EQ(s.inputs[j].above, above[j]) << box[j].name;
      if (below[j] > 0) {
        EXPECT_EQ(s.inputs[j].lowest, lowest[j]);
      }
      if (above[j] > 0) {
        EXPECT_EQ(s.inputs[j].highest, highest[j]);
      }
    }
    EXPECT_EQ(log.rows("gp"), max_rows);  // the row cap bites, the counts went on
  }  // the log's destructor writes the summary
  const CsvTable table = read_csv_table((dir / "gp.csv").string());
  ASSERT_EQ(table.rows.size(), static_cast<size_t>(max_rows));
  const auto p = table.si_column("contact_pressure"), flagged = table.si_column("outside_inputs");
  size_t k = 0;
  for (size_t i = 0; i < pts.p.size() && k < p.size(); ++i) {
    const bool out = !box[0].contains(pts.p[i]) || !box[1].contains(pts.v[i]) || !box[2].contains(pts.t[i]);
    if (!out) continue;
    EXPECT_EQ(p[k], pts.p[i]);
    EXPECT_EQ(flagged[k], 1.0);
    ++k;
  }
  const auto json = nlohmann::json::parse(std::ifstream(dir / "gp.outside.json"));
  EXPECT_EQ(json.at("outside_queries").get<long long>(), outside);
  EXPECT_EQ(json.at("inputs").at(2).at("name"), "temperature");
  EXPECT_EQ(json.at("inputs").at(2).at("above").get<long long>(), above[2]);
  EXPECT_EQ(json.at("inputs").at(1).at("lowest").get<double>(), lowest[1]);
}

// A full log is renamed NAME.csv.1 (replacing the one before) and a new one begun, so that logging
// follows the queries with bounded disk use; a server started on a part-full file counts its rows.
TEST(UncertainLog, AFullLogIsRenamedAndANewOneBegun) {
  const fs::path dir = fs::path(::testing::TempDir()) / "rotating-log";
  fs::remove_all(dir);
  const InputSpace box = default_friction_box();
  const auto batch = [&box](double pressure) {  // six points below the box's pressures: all logged
    Eigen::MatrixXd x(6, 3);
    for (Eigen::Index i = 0; i < 6; ++i) x.row(i) << pressure + 1e6 * static_cast<double>(i), box[1].lo, box[2].lo;
    return x;
  };
  const Eigen::VectorXd std = Eigen::VectorXd::Zero(6);
  const auto pressures = [](const fs::path& file) { return read_csv_table(file.string()).si_column("contact_pressure"); };
  {
    UncertainQueryLog log(dir.string(), 1e6, 10);
    log.record("gp", box, batch(10e6), std);
    EXPECT_FALSE(fs::exists(dir / "gp.csv.1"));
    log.record("gp", box, batch(20e6), std);  // 12 rows would pass 10: the first six are renamed away
    EXPECT_EQ(pressures(dir / "gp.csv.1").front(), 10e6);
    EXPECT_EQ(pressures(dir / "gp.csv").front(), 20e6);
    EXPECT_EQ(log.rows("gp"), 6);
  }
  UncertainQueryLog restarted(dir.string(), 1e6, 10);
  restarted.record("gp", box, batch(30e6), std);  // the file's six rows count: renamed again
  EXPECT_EQ(pressures(dir / "gp.csv.1").front(), 20e6);
  const auto current = pressures(dir / "gp.csv");
  ASSERT_EQ(current.size(), 6u);
  EXPECT_EQ(current.front(), 30e6);
}

// A model reloaded with a grown box: counts against the old box would mislead, so they restart
// and the summary on disk is rewritten against the new box.
TEST_F(Service, OutsideCountsRestartWhenTheModelsBoxChanges) {
  const InputSpace old_box = default_friction_box();
  InputSpace grown = old_box;
  grown[0].hi = 3e9;
  Eigen::MatrixXd x(2, 3);
  x << 2e9, 1.0, 400.0,  // above the old box's pressure, inside the grown one
      4e9, 1.0, 400.0;   // above both
  const Eigen::VectorXd std = Eigen::VectorXd::Zero(2);
  const fs::path dir = dir_ / "regrown";
  UncertainQueryLog log(dir.string(), 1e6, 100);
  log.record("gp", old_box, x, std);
  EXPECT_EQ(log.outside("gp").outside_queries, 2);
  EXPECT_EQ(log.outside("gp").inputs[0].above, 2);
  log.flush();
  log.record("gp", grown, x, std);
  const OutsideSummary s = log.outside("gp");
  EXPECT_EQ(s.queries, 2);
  EXPECT_EQ(s.outside_queries, 1);
  EXPECT_EQ(s.inputs[0].above, 1);
  EXPECT_EQ(s.inputs[0].highest, 4e9);
  log.flush();
  const auto json = nlohmann::json::parse(std::ifstream(dir / "gp.outside.json"));
  EXPECT_EQ(json.at("outside_queries").get<long long>(), 1);
  EXPECT_EQ(json.at("inputs").at(0).at("box_hi").get<double>(), 3e9);
}

// A GP heavy enough that its std takes a while: fixed hyper-parameters, `points` training points
// (80 000 points with std take about half a second at 1000: L⁻¹ of 1000² per point).
void save_heavy_gp(const fs::path& file, Eigen::Index points) {
  GpTrainingOptions options;
  options.optimise = false;
  options.initial.length_scales = Eigen::Vector3d(0.3, 0.3, 0.3);
  options.initial.noise_variance = 1e-4;
  save_model(file.string(), train_gaussian_process(test::smooth_training_set(points, 5), options));
}

// An Evaluate request of `model` at the points, for calls made with the raw stub.
mufric::v1::EvaluateRequest request_of(const std::string& model, const Points& pts) {
  mufric::v1::EvaluateRequest request;
  request.set_model(model);
  request.mutable_contact_pressure()->Add(pts.p.begin(), pts.p.end());
  request.mutable_sliding_velocity()->Add(pts.v.begin(), pts.v.end());
  request.mutable_temperature()->Add(pts.t.begin(), pts.t.end());
  return request;
}

TEST_F(Service, StreamOfIncrementsAnswersLikeUnaryCallsAndSurvivesAnError) {
  LoopbackServer server(dir_);
  client::Options streaming;
  streaming.streaming = true;
  streaming.chunk_points = 100;
  const auto stream = client::connect("grpc://" + server.address() + "/gp", streaming);
  const auto unary = client::connect("grpc://" + server.address() + "/gp");
  const EvaluationRequest what{.std = true, .ci_level = 0.95};
  for (int increment = 0; increment < 5; ++increment) {  // a meso job: one block per increment
    const Points pts = random_points(250 + static_cast<size_t>(increment));
    const client::Answer a = stream->evaluate(pts.block(), what), b = unary->evaluate(pts.block(), what);
    ASSERT_EQ(a.mu.size(), pts.p.size());
    EXPECT_EQ(a.mu, b.mu);
    EXPECT_EQ(a.hi, b.hi);
  }
  // A block without temperature ends that stream with INVALID_ARGUMENT; the next block reopens it.
  Points bad = random_points(3);
  client::Block missing = bad.block();
  missing.temperature = nullptr;
  try {
    stream->evaluate(missing, {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("INVALID_ARGUMENT"), std::string::npos) << e.what();
  }
  EXPECT_EQ(stream->evaluate(bad.block(), {}).mu.size(), 3u);
}

TEST_F(Service, BadPointsGetTheirStatusAndNeverPoisonTheBlock) {
  LoopbackServer server(dir_);
  const auto remote = client::connect("grpc://" + server.address() + "/gp");
  Points pts = random_points(4);
  pts.p[1] = std::numeric_limits<double>::quiet_NaN();
  pts.v[2] = -1.0;
  pts.t[3] = 5000.0;  // outside the training box
  const client::Answer a = remote->evaluate(pts.block(), {.std = true, .ci_level = 0.9});
  EXPECT_EQ(a.status, (std::vector<PointStatus>{PointStatus::ok, PointStatus::invalid_input, PointStatus::invalid_input,
                                                PointStatus::extrapolated}));
  EXPECT_TRUE(std::isfinite(a.mu[0]) && std::isfinite(a.mu[3]));
  EXPECT_TRUE(std::isnan(a.mu[1]) && std::isnan(a.std[2]) && std::isnan(a.lo[1]));
}

grpc::Status raw_evaluate(const std::string& address, const mufric::v1::EvaluateRequest& request) {
  auto stub = mufric::v1::FrictionService::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  mufric::v1::EvaluateResponse response;
  return stub->Evaluate(&context, request, &response);
}

TEST_F(Service, MalformedRequestsAreRefusedNamingTheProblem) {
  LoopbackServer server(dir_, 0, {.max_points_per_request = 1000, .bearer_token = {}});
  mufric::v1::EvaluateRequest request;
  request.set_model("gp");
  for (int i = 0; i < 3; ++i) request.add_contact_pressure(500e6);
  for (int i = 0; i < 2; ++i) request.add_sliding_velocity(1.0);
  for (int i = 0; i < 3; ++i) request.add_temperature(600.0);
  grpc::Status s = raw_evaluate(server.address(), request);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("sliding_velocity has 2 values but contact_pressure has 3"), std::string::npos)
      << s.error_message();

  request.clear_sliding_velocity();
  s = raw_evaluate(server.address(), request);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("sliding_velocity is empty"), std::string::npos) << s.error_message();

  request.set_model("nope");
  s = raw_evaluate(server.address(), request);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(s.error_message().find("serving: coulomb, gp"), std::string::npos) << s.error_message();

  mufric::v1::EvaluateRequest big;
  big.set_model("coulomb");
  for (int i = 0; i < 1001; ++i) {
    big.add_contact_pressure(500e6);
    big.add_sliding_velocity(1.0);
    big.add_temperature(600.0);
  }
  s = raw_evaluate(server.address(), big);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(s.error_message().find("limit of 1000"), std::string::npos) << s.error_message();

  big.set_ci_level(1.5);
  s = raw_evaluate(server.address(), big);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("ci_level"), std::string::npos);
}

TEST_F(Service, HotReloadUnderLoadFailsNoRequestAndRefusesABadFile) {
  LoopbackServer server(dir_);
  const auto remote = client::connect("grpc://" + server.address() + "/coulomb");
  const Points pts = random_points(64);
  std::atomic<bool> done{false};
  std::atomic<long long> calls{0}, failures{0};
  std::vector<std::thread> load;
  for (int t = 0; t < 4; ++t) {
    load.emplace_back([&] {
      const auto c = client::connect("grpc://" + server.address() + "/coulomb");
      while (!done) {
        try {
          const auto a = c->evaluate(pts.block(), {});
          if (a.mu.size() != 64 || !(a.mu[0] >= 0.3 && a.mu[0] <= 0.32)) ++failures;
        } catch (const Error&) {
          ++failures;
        }
        ++calls;
      }
    });
  }
  for (int k = 1; k <= 20; ++k) {
    save_model((dir_ / "coulomb.h5").string(), CoulombLaw(0.3 + 0.001 * k));  // atomic rename
    server.registry().refresh();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  { std::ofstream((dir_ / "coulomb.h5").string()) << "not a model any more"; }
  server.registry().refresh();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  done = true;
  for (auto& t : load) t.join();
  EXPECT_GT(calls.load(), 50);
  EXPECT_EQ(failures.load(), 0);
  // The bad file was refused: the last good version (μ = 0.32) keeps serving.
  EXPECT_DOUBLE_EQ(remote->evaluate(pts.block(), {}).mu[0], 0.32);
}

// Established TCP connections whose local port is `port` (the server's side), from /proc/net/tcp
// and tcp6 (gRPC listens on an IPv6 socket, IPv4 addresses mapped into it).
int established_connections_to(int port) {
  int count = 0;
  constexpr const char* kEstablished = "01";
  for (const char* path : {"/proc/self/net/tcp", "/proc/self/net/tcp6"}) {
    std::ifstream table(path);
    std::string line;
    std::getline(table, line);  // header
    while (std::getline(table, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, state;
      fields >> slot >> local >> remote >> state;
      const int local_port = std::stoi(local.substr(local.find(':') + 1), nullptr, 16);
      count += local_port == port && state == kEstablished;
    }
  }
  return count;
}

// Regression: `bench --clients 8` said "each with its own connection" and opened one (gRPC shares a
// connection among channels to one target). Options::own_connection gives each client its own.
TEST_F(Service, ClientsWithTheirOwnConnectionOpenOneEach) {
  const Points pts = random_points(2);
  LoopbackServer shared_server(dir_), own_server(dir_);
  const std::string shared_uri = "grpc://" + shared_server.address() + "/coulomb";
  const auto a = client::connect(shared_uri), b = client::connect(shared_uri);
  a->evaluate(pts.block(), {});
  b->evaluate(pts.block(), {});
  EXPECT_EQ(established_connections_to(shared_server.port()), 1);
  client::Options own;
  own.own_connection = true;
  const std::string own_uri = "grpc://" + own_server.address() + "/coulomb";
  const auto c = client::connect(own_uri, own), d = client::connect(own_uri, own);
  c->evaluate(pts.block(), {});
  d->evaluate(pts.block(), {});
  EXPECT_EQ(established_connections_to(own_server.port()), 2);
}

// A registry over dir/ whose log lines are kept, for the reload tests.
struct LoggedRegistry {
  explicit LoggedRegistry(const fs::path& dir)
      : registry(dir, [this](const std::string& level, const std::string& line) { log += level + ": " + line + "\n"; }) {}
  std::string log;
  server::ModelRegistry registry;
};

std::string served_version(const server::ModelRegistry& registry, const std::string& name) {
  const auto served = registry.find(name);
  return served ? served->version : "(not served)";
}

std::string file_version(const fs::path& path) { return sha256_file(path.string()).substr(0, 16); }

// Regression: reload compared size and modification time only, so a different model written in
// place with the same size and a pinned time (deploy tools that keep file times) was never loaded.
TEST_F(Service, AModelReplacedWithTheSameSizeAndTimeIsLoaded) {
  const fs::path served = dir_ / "coulomb.h5", other = dir_ / "other.dat";
  save_model(other.string(), CoulombLaw(0.45));
  ASSERT_EQ(fs::file_size(other), fs::file_size(served)) << "the test needs two models of one size";
  LoggedRegistry logged(dir_);
  logged.registry.refresh();
  ASSERT_EQ(served_version(logged.registry, "coulomb"), file_version(served));
  const auto pinned_time = fs::last_write_time(served);
  std::ifstream in(other, std::ios::binary);
  std::ofstream(served, std::ios::binary | std::ios::trunc) << in.rdbuf();  // same inode, new bytes
  fs::last_write_time(served, pinned_time);
  EXPECT_EQ(logged.registry.refresh(), 1) << logged.log;
  EXPECT_EQ(served_version(logged.registry, "coulomb"), file_version(other));
  // The same bytes under a new time are not reloaded, on the poll or on SIGHUP's rescan by content.
  fs::last_write_time(served, pinned_time + std::chrono::seconds(5));
  EXPECT_EQ(logged.registry.refresh(), 0);
  EXPECT_EQ(logged.registry.refresh(server::ModelRegistry::Rescan::kByContent), 0);
  EXPECT_EQ(served_version(logged.registry, "coulomb"), file_version(other));
}

// A campaign's model with a law coefficient among its inputs is no friction law a meso code can call:
// the registry refuses it (its μ would depend on a value the wire cannot carry), and the in-process
// client says why; both name the input.
TEST_F(Service, AModelWithALawCoefficientAmongItsInputsIsNotServed) {
  TrainingSet data = test::smooth_training_set(20, 3);
  data.inputs.back() = {"shear_factor", "1", 0.2, 0.9};
  for (Eigen::Index i = 0; i < data.x.rows(); ++i) data.x(i, 2) = 0.2 + 0.7 * static_cast<double>(i) / 19.0;
  GpTrainingOptions options;
  options.optimise = false;
  const fs::path campaign = dir_ / "campaign.h5";
  save_model(campaign.string(), train_gaussian_process(data, options));
  LoggedRegistry logged(dir_);
  logged.registry.refresh();
  EXPECT_EQ(served_version(logged.registry, "campaign"), "(not served)");
  EXPECT_NE(logged.log.find("not served: its input 'shear_factor' is a coefficient of the interface law"), std::string::npos)
      << logged.log;
  EXPECT_NE(served_version(logged.registry, "coulomb"), "(not served)");  // the others are
  try {
    client::connect(campaign.string());
    ADD_FAILURE() << "the campaign's model was opened";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'shear_factor'"), std::string::npos) << e.what();
  }
}

// Regression: deleting a served file stopped its model (an rm-then-cp deploy answered NOT_FOUND
// for 12 s). The loaded version keeps serving, and the log says so, until a new file replaces it.
TEST_F(Service, ADeletedModelFileKeepsServingUntilANewFileReplacesIt) {
  LoopbackServer server(dir_);
  const fs::path served = dir_ / "coulomb.h5";
  const std::string first = file_version(served);
  LoggedRegistry logged(dir_);
  logged.registry.refresh();
  fs::remove(served);
  server.registry().refresh();
  logged.registry.refresh();
  logged.registry.refresh();
  EXPECT_EQ(served_version(logged.registry, "coulomb"), first);
  EXPECT_NE(logged.log.find("coulomb.h5 is gone; version " + first + " keeps serving"), std::string::npos) << logged.log;
  EXPECT_EQ(logged.log.find("is gone", logged.log.find("is gone") + 1), std::string::npos) << "logged once: " << logged.log;
  const Points pts = random_points(8);
  const auto remote = client::connect("grpc://" + server.address() + "/coulomb");
  EXPECT_DOUBLE_EQ(remote->evaluate(pts.block(), {}).mu[0], 0.3);
  save_model(served.string(), CoulombLaw(0.35));
  server.registry().refresh();
  logged.registry.refresh();
  EXPECT_EQ(served_version(logged.registry, "coulomb"), file_version(served));
  EXPECT_NE(logged.log.find("coulomb.h5 is back"), std::string::npos) << logged.log;
  EXPECT_DOUBLE_EQ(remote->evaluate(pts.block(), {}).mu[0], 0.35);
}

// Regression: a model file whose global-heap string length had one flipped byte, dropped into the
// served directory, killed `mufric serve` with SIGSEGV. It is now refused, and every other model
// keeps serving (this test process is the server: a crash would end it).
TEST_F(Service, FileThatCrashesTheHdf5LibraryIsRefusedAndTheServerLives) {
  LoopbackServer server(dir_);
  fs::copy_file(dir_ / "gp.h5", dir_ / "corrupt.h5");
  test::flip_global_heap_string_length((dir_ / "corrupt.h5").string());
  server.registry().refresh();
  EXPECT_EQ(server.registry().find("corrupt"), nullptr);
  const Points pts = random_points(8);
  const auto gp = client::connect("grpc://" + server.address() + "/gp");
  EXPECT_EQ(gp->evaluate(pts.block(), {}).mu.size(), 8u);
  EXPECT_THROW(client::connect("grpc://" + server.address() + "/corrupt")->evaluate(pts.block(), {}), Error);
}

TEST_F(Service, ClientReconnectsAfterTheServerRestarts) {
  auto server = std::make_unique<LoopbackServer>(dir_);
  const int port = server->port();
  // Eight retries back off over 12.8 s in all: the new server (loading and checking its models in
  // children) took longer than the default four retries' 0.75 s under the sanitizers on a busy machine.
  client::Options patient;
  patient.retries = 8;
  const auto remote = client::connect("grpc://127.0.0.1:" + std::to_string(port) + "/coulomb", patient);
  const Points pts = random_points(8);
  EXPECT_DOUBLE_EQ(remote->evaluate(pts.block(), {}).mu[0], 0.3);
  server.reset();  // killed
  std::thread restart([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    server = std::make_unique<LoopbackServer>(dir_, port);
  });
  // The call made while the server is down is retried with backoff until the new one is up.
  double mu = 0.0;
  std::string error;
  try {
    mu = remote->evaluate(pts.block(), {}).mu[0];
  } catch (const Error& e) {
    error = e.what();
  }
  restart.join();
  EXPECT_EQ(error, "");
  EXPECT_DOUBLE_EQ(mu, 0.3);
}

TEST_F(Service, BearerTokenIsRequiredWhenConfigured) {
  LoopbackServer server(dir_, 0, {.max_points_per_request = 1000000, .bearer_token = "s3cret"});
  const Points pts = random_points(2);
  client::Options without;
  without.retries = 0;
  try {
    client::connect("grpc://" + server.address() + "/coulomb", without)->evaluate(pts.block(), {});
    FAIL() << "expected UNAUTHENTICATED";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("UNAUTHENTICATED"), std::string::npos) << e.what();
  }
  // A refused call is a request and an error (regression: an error but not a request).
  EXPECT_EQ(server.service().counters().requests.load(), 1);
  EXPECT_EQ(server.service().counters().errors.load(), 1);
  client::Options with = without;
  with.token = "s3cret";
  EXPECT_DOUBLE_EQ(client::connect("grpc://" + server.address() + "/coulomb", with)->evaluate(pts.block(), {}).mu[0], 0.3);
  with.streaming = true;
  EXPECT_DOUBLE_EQ(client::connect("grpc://" + server.address() + "/coulomb", with)->evaluate(pts.block(), {}).mu[0], 0.3);
  // The scheme is case-insensitive (RFC 7235 §2.1); the token is not.
  const auto list_with = [&](const std::string& authorization) {
    auto stub = mufric::v1::FrictionService::NewStub(grpc::CreateChannel(server.address(), grpc::InsecureChannelCredentials()));
    grpc::ClientContext context;
    context.AddMetadata("authorization", authorization);
    mufric::v1::ListModelsResponse response;
    return stub->ListModels(&context, {}, &response).error_code();
  };
  EXPECT_EQ(list_with("bearer s3cret"), grpc::StatusCode::OK);
  EXPECT_EQ(list_with("BEARER s3cret"), grpc::StatusCode::OK);
  EXPECT_EQ(list_with("Bearer S3CRET"), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(list_with("Basic s3cret"), grpc::StatusCode::UNAUTHENTICATED);
}

// A test CA, a server certificate for 127.0.0.1 and a client certificate, made with openssl.
void make_certificates(const fs::path& d) {
  const std::string dir = d.string();
  const std::string key = " -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes ";
  const std::string script =
      "cd " + dir + " && openssl req -x509" + key + "-keyout ca.key -out ca.pem -days 1 -subj /CN=mufric-test-ca" +
      " && openssl req" + key + "-keyout server.key -out server.csr -subj /CN=localhost" +
      " && printf 'subjectAltName=IP:127.0.0.1,DNS:localhost' > san.ext" +
      " && openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out server.pem -days 1 -extfile san.ext" +
      " && openssl req" + key + "-keyout client.key -out client.csr -subj /CN=meso-client" +
      " && openssl x509 -req -in client.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out client.pem -days 1";
  ASSERT_EQ(std::system(("(" + script + ") >/dev/null 2>&1").c_str()), 0) << "openssl failed";
}

TEST_F(Service, TlsAndMutualTls) {
  make_certificates(dir_);
  const Points pts = random_points(2);
  server::ServerOptions tls;
  tls.tls_cert = (dir_ / "server.pem").string();
  tls.tls_key = (dir_ / "server.key").string();
  client::Options options;
  options.retries = 0;
  options.deadline_seconds = 5;
  options.tls_ca_file = (dir_ / "ca.pem").string();
  {
    LoopbackServer server(dir_, 0, {}, server::server_credentials(tls));
    EXPECT_DOUBLE_EQ(client::connect("grpcs://" + server.address() + "/coulomb", options)->evaluate(pts.block(), {}).mu[0], 0.3);
    // Regression: a plaintext client of a TLS server was told "tcp handshaker shutdown" only.
    try {
      client::connect("grpc://" + server.address() + "/coulomb", options)->evaluate(pts.block(), {});
      ADD_FAILURE() << "a plaintext client reached a TLS server";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("does the server use TLS? then connect with grpcs://"), std::string::npos)
          << e.what();
    }
  }
  tls.tls_client_ca = (dir_ / "ca.pem").string();
  LoopbackServer server(dir_, 0, {}, server::server_credentials(tls));
  EXPECT_THROW(client::connect("grpcs://" + server.address() + "/coulomb", options)->evaluate(pts.block(), {}), Error);
  options.tls_cert_file = (dir_ / "client.pem").string();
  options.tls_key_file = (dir_ / "client.key").string();
  EXPECT_DOUBLE_EQ(client::connect("grpcs://" + server.address() + "/coulomb", options)->evaluate(pts.block(), {}).mu[0], 0.3);
}

TEST_F(Service, StatusCountsRequestsPointsErrorsAndLatencies) {
  LoopbackServer server(dir_);
  const auto remote = client::connect("grpc://" + server.address() + "/coulomb");
  const Points pts = random_points(10);
  for (int i = 0; i < 3; ++i) remote->evaluate(pts.block(), {});
  client::Options quick;
  quick.retries = 0;
  EXPECT_THROW(client::connect("grpc://" + server.address() + "/nope", quick)->evaluate(pts.block(), {}), Error);
  const client::ServerStatus s = client::server_status("grpc://" + server.address());
  // Three Evaluate calls of 10 points answered, one for an unknown model refused (NOT_FOUND).
  EXPECT_EQ(s.points, 30);
  EXPECT_GE(s.errors, 1);
  long long evaluations = 0;
  for (const long long c : s.latency_counts) evaluations += c;
  EXPECT_EQ(evaluations, 4);  // three answered, one NOT_FOUND
  EXPECT_EQ(s.latency_counts.size(), s.latency_bounds_us.size() + 1);
  EXPECT_EQ(s.models.size(), 2u);
}

TEST_F(Service, AnEvaluationWhoseDeadlinePassedStopsEarly) {
  // A GP heavy enough that 80 000 points with std take about half a second (L⁻¹ of 1000² per point;
  // ten chunks of 8192 points).
  save_heavy_gp(dir_ / "heavy.h5", 1000);
  const Points pts = random_points(80'000);
  const EvaluationRequest what{.std = true};
  const auto start_local = std::chrono::steady_clock::now();
  client::connect("file://" + (dir_ / "heavy.h5").string())->evaluate(pts.block(), what);
  const double full_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_local).count();

  LoopbackServer server(dir_);
  client::Options impatient;
  impatient.deadline_seconds = full_seconds / 8;
  impatient.retries = 0;
  impatient.chunk_points = 200'000;  // one call
  const auto start = std::chrono::steady_clock::now();
  try {
    client::connect("grpc://" + server.address() + "/heavy", impatient)->evaluate(pts.block(), what);
    ADD_FAILURE() << "the call should have missed its deadline of " << impatient.deadline_seconds << " s";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("eadline"), std::string::npos) << e.what();
  }
  // The server must stop within a chunk or two of the deadline, not finish the whole batch.
  while (server.service().counters().in_flight.load() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const double busy_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(server.service().counters().abandoned.load(), 1);
  EXPECT_LT(busy_seconds, full_seconds / 2) << "in-process evaluation of the whole batch takes " << full_seconds << " s";
}

// The memory budget's arithmetic against sums done by hand.
TEST(MemoryBudget, AdmitsWhatFitsBesideTheCallsInFlightAndALoneCallWhateverItsSize) {
  server::MemoryBudget budget(100);
  auto first = budget.try_reserve(60);
  ASSERT_TRUE(first);
  EXPECT_FALSE(budget.try_reserve(41));  // 60 + 41 > 100
  auto second = budget.try_reserve(40);  // 60 + 40 = 100 fits
  ASSERT_TRUE(second);
  EXPECT_EQ(budget.in_use(), 100u);
  first.release();
  second = {};
  EXPECT_EQ(budget.in_use(), 0u);
  {
    const auto alone = budget.try_reserve(1000);  // larger than the budget, but nothing else runs
    ASSERT_TRUE(alone);
    EXPECT_FALSE(budget.try_reserve(1));
  }
  EXPECT_EQ(budget.in_use(), 0u);
}

// Freed memory goes back once per busy spell, on its transition to idle (issue 63: it was trimmed
// every second while the resident size stayed high for reasons a trim cannot fix).
TEST(IdleTrimmer, TrimsOnceOnEachTransitionFromBusyToIdle) {
  server::IdleTrimmer trimmer;
  EXPECT_FALSE(trimmer.poll(0, true));   // nothing served yet
  EXPECT_FALSE(trimmer.poll(5, false));  // busy
  EXPECT_TRUE(trimmer.poll(5, true));    // idle after a spell: once
  for (int second = 0; second < 10; ++second) EXPECT_FALSE(trimmer.poll(5, true));  // still idle: never again
  EXPECT_FALSE(trimmer.poll(9, false));
  EXPECT_TRUE(trimmer.poll(9, true));
  EXPECT_EQ(trimmer.trims(), 2);
}

// evaluation_bytes counts the request, the batch and the answer twice.
TEST(MemoryBudget, AnEvaluationsBytesAreItsRequestBatchAndTwoAnswers) {
  mufric::v1::EvaluateRequest request;
  request.set_model("gp");
  for (int i = 0; i < 1000; ++i) {
    request.add_contact_pressure(1e9);
    request.add_sliding_velocity(1.0);
    request.add_temperature(500.0);
  }
  request.set_std(true);
  request.set_ci_level(0.95);
  request.set_gradient(true);
  // Answer per point: mu, std, lo, hi and 3 gradient entries (7 doubles) and a status byte.
  const std::size_t expected = request.ByteSizeLong() + 1000 * 3 * 8 + 2 * 1000 * (7 * 8 + 1);
  EXPECT_EQ(server::evaluation_bytes(request, 3, false), expected);
  EXPECT_EQ(server::evaluation_bytes(request, 3, true), expected + 2 * 1000 * 8);
}

// A server whose memory for calls in flight is taken refuses with RESOURCE_EXHAUSTED and a retry
// hint; mufric's client follows the hint and gets its answer once the other call is done.
TEST_F(Service, ABusyServerRefusesWithARetryHintAndTheClientWaitsItsTurn) {
  save_heavy_gp(dir_ / "heavy.h5", 500);
  const Points pts = random_points(40'000);
  mufric::v1::EvaluateRequest request = request_of("heavy", pts);
  request.set_std(true);
  server::ServiceLimits limits;
  limits.request_memory_bytes = server::evaluation_bytes(request, 3, false) * 3 / 2;  // one such call at a time
  LoopbackServer server(dir_, 0, limits);
  const EvaluationRequest what{.std = true};
  client::Options one_call;
  one_call.chunk_points = 100'000;
  std::thread first([&] { client::connect("grpc://" + server.address() + "/heavy", one_call)->evaluate(pts.block(), what); });
  while (server.service().memory().in_use() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  auto stub = mufric::v1::FrictionService::NewStub(grpc::CreateChannel(server.address(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  mufric::v1::EvaluateResponse response;
  const grpc::Status refused = stub->Evaluate(&context, request, &response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
  EXPECT_NE(refused.error_message().find("--max-memory-mb"), std::string::npos) << refused.error_message();
  const auto hint = context.GetServerTrailingMetadata().find(wire::kRetryAfterKey);
  ASSERT_NE(hint, context.GetServerTrailingMetadata().end());
  EXPECT_EQ(std::string(hint->second.data(), hint->second.size()), std::to_string(server::kRetryAfterMs));
  // The client waits its turn while the first call runs, and both are answered.
  const client::Answer answer = client::connect("grpc://" + server.address() + "/heavy", one_call)->evaluate(pts.block(), what);
  first.join();
  EXPECT_EQ(answer.mu.size(), pts.p.size());
  EXPECT_GE(server.service().counters().refused_busy.load(), 1);
  const client::ServerStatus status = client::server_status("grpc://" + server.address());
  EXPECT_EQ(status.refused_busy, server.service().counters().refused_busy.load());
  EXPECT_EQ(status.memory_limit_bytes, static_cast<long long>(limits.request_memory_bytes));
  // Given back once gRPC has sent the last answer (the reactor's OnDone, just after the client has it).
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (server.service().memory().in_use() > 0 && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(server.service().memory().in_use(), 0u);
}

// A stream beyond --max-streams is refused with the retry hint; a stream whose client does not take
// its answer is cancelled after stream_write_seconds, and its memory is given back.
TEST_F(Service, StreamsAreBoundedInNumberAndInHowLongAnAnswerWaitsForItsReader) {
  server::ServiceLimits limits;
  limits.max_streams = 1;
  limits.stream_write_seconds = 0.5;
  LoopbackServer server(dir_, 0, limits);
  // A 100 000-point answer with std and interval (3.3 MB; gRPC's default limit is 4 MB) is far more
  // than this client's fixed 64 kB flow-control window (no BDP probing, which would grow it): it
  // waits for a reader that never comes.
  grpc::ChannelArguments small_window;
  small_window.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  small_window.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 65536);
  auto stub = mufric::v1::FrictionService::NewStub(
      grpc::CreateCustomChannel(server.address(), grpc::InsecureChannelCredentials(), small_window));
  const Points pts = random_points(100'000);
  mufric::v1::EvaluateRequest request = request_of("gp", pts);
  request.set_std(true);
  request.set_ci_level(0.95);
  grpc::ClientContext unread_context;
  auto unread = stub->EvaluateStream(&unread_context);
  ASSERT_TRUE(unread->Write(request));
  while (server.service().counters().open_streams.load() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  {
    grpc::ClientContext context;
    auto second = stub->EvaluateStream(&context);
    mufric::v1::EvaluateResponse response;
    EXPECT_FALSE(second->Read(&response));
    const grpc::Status refused = second->Finish();
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
    EXPECT_NE(refused.error_message().find("--max-streams"), std::string::npos) << refused.error_message();
    EXPECT_NE(context.GetServerTrailingMetadata().find(wire::kRetryAfterKey), context.GetServerTrailingMetadata().end());
  }
  const auto start = std::chrono::steady_clock::now();
  while (server.service().counters().stalled_streams.load() == 0 &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(server.service().counters().stalled_streams.load(), 1);
  while (server.service().counters().open_streams.load() > 0 && std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(server.service().counters().open_streams.load(), 0);
  EXPECT_EQ(server.service().memory().in_use(), 0u);
  EXPECT_EQ(server.service().counters().refused_streams.load(), 1);
  const client::ServerStatus status = client::server_status("grpc://" + server.address());
  EXPECT_EQ(status.stalled_streams, 1);
  EXPECT_EQ(status.refused_streams, 1);
  EXPECT_EQ(status.open_streams, 0);
  unread_context.TryCancel();
  unread->Finish();
}

TEST(ServiceThreads, ConcurrentEvaluationsShareTheCores) {
  EXPECT_EQ(server::threads_per_evaluation(8, 1), 8);
  EXPECT_EQ(server::threads_per_evaluation(8, 3), 2);
  EXPECT_EQ(server::threads_per_evaluation(2, 32), 1);
  EXPECT_EQ(server::threads_per_evaluation(2, 0), 2);
}

TEST_F(Service, StandardHealthServiceAnswersServing) {
  LoopbackServer server(dir_);
  auto channel = grpc::CreateChannel(server.address(), grpc::InsecureChannelCredentials());
  grpc::ClientContext context;
  grpc::ByteBuffer response;
  // grpc.health.v1.Health/Check with an empty HealthCheckRequest (service ""): SERVING is 08 01.
  grpc::GenericStub stub(channel);
  grpc::Slice empty_request("", 0);
  grpc::ByteBuffer request(&empty_request, 1);
  std::mutex m;
  std::condition_variable cv;
  bool finished = false;
  grpc::Status status;
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &request, &response,
                 [&](grpc::Status s) {
                   std::lock_guard lock(m);
                   status = s;
                   finished = true;
                   cv.notify_one();
                 });
  std::unique_lock lock(m);
  cv.wait(lock, [&] { return finished; });
  ASSERT_TRUE(status.ok()) << status.error_message();
  std::vector<grpc::Slice> slices;
  ASSERT_TRUE(response.Dump(&slices).ok());
  std::string bytes;
  for (const auto& s : slices) bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  EXPECT_EQ(bytes, std::string("\x08\x01", 2));
}

}  // namespace
}  // namespace mufric

namespace mufric {
namespace {

TEST(ClientOptions, ParsedFromTextNamingWhatIsWrong) {
  const client::Options o = client::parse_options(
      " deadline=2.5, retries=1;backoff=0.01 chunk_points=4096, max_message_mb=8, stream=yes, token=abc, "
      "tls_ca=/ca.pem, tls_cert=/c.pem, tls_key=/k.pem");
  EXPECT_EQ(o.deadline_seconds, 2.5);
  EXPECT_EQ(o.retries, 1);
  EXPECT_EQ(o.first_backoff_seconds, 0.01);
  EXPECT_EQ(o.chunk_points, 4096);
  EXPECT_EQ(o.max_message_mb, 8);
  EXPECT_TRUE(o.streaming);
  EXPECT_EQ(o.token, "abc");
  EXPECT_EQ(o.tls_ca_file, "/ca.pem");
  EXPECT_EQ(o.tls_cert_file, "/c.pem");
  EXPECT_EQ(o.tls_key_file, "/k.pem");
  EXPECT_EQ(client::parse_options("").deadline_seconds, client::Options{}.deadline_seconds);

  auto refusal = [](const std::string& text) {
    try {
      client::parse_options(text);
    } catch (const client::InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal("deadlin=2").find("'deadlin' is unknown"), std::string::npos) << refusal("deadlin=2");
  EXPECT_NE(refusal("deadline=soon").find("deadline: 'soon' is not a number"), std::string::npos);
  EXPECT_NE(refusal("deadline=0").find("outside"), std::string::npos);
  EXPECT_NE(refusal("retries=1.5").find("not a whole number"), std::string::npos);
  EXPECT_NE(refusal("stream=maybe").find("stream: 'maybe'"), std::string::npos);
  EXPECT_NE(refusal("stream").find("expected key=value"), std::string::npos);
  EXPECT_EQ(client::parse_options("fill=-1").fill, -1.0);
  EXPECT_FALSE(client::parse_options("").fill.has_value());
  EXPECT_NE(refusal("fill=nan").find("fill: 'nan' is not a number"), std::string::npos) << refusal("fill=nan");
  EXPECT_NE(refusal("fill=-inf").find("fill: '-inf' is not a number"), std::string::npos);
}

// A served model with a fast evaluator: the response and the status count the points it answered;
// a negative tolerance (the C ABI's mu_tolerance=0) asks for the exact model.
TEST_F(Service, FastEvaluatorPointsAreCountedAndCanBeRefused) {
  {
    auto gp = std::unique_ptr<FrictionModel>(load_model((dir_ / "gp.h5").string()));
    auto& trained = dynamic_cast<GaussianProcess&>(*gp);
    FastEvaluatorOptions o;
    o.check_points = 2000;
    trained.attach_fast_evaluator(std::make_shared<const FastEvaluator>(build_fast_evaluator(trained, o)));
    save_model((dir_ / "fast.h5").string(), trained);
  }
  LoopbackServer server(dir_);
  const Points pts = random_points(40);
  const std::string uri = "grpc://" + server.address() + "/fast";
  const auto client = client::connect(uri);
  EXPECT_EQ(client->evaluate(pts.block(), {.ci_level = 0.95}).fast_points, 40);
  EvaluationRequest exact{.ci_level = 0.95};
  exact.mu_tolerance = 0.0;
  EXPECT_EQ(client->evaluate(pts.block(), exact).fast_points, 0);
  EXPECT_EQ(client::server_status("grpc://" + server.address()).fast_points, 40);

  mufric_client* c = nullptr;
  std::vector<double> mu(40), lo(40), hi(40);
  for (const char* options : {"", "mu_tolerance=0"}) {
    ASSERT_EQ(mufric_open_with_options(uri.c_str(), options, &c), MUFRIC_OK) << mufric_last_error();
    ASSERT_EQ(mufric_evaluate(c, 40, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, 0.95, mu.data(), nullptr,
                              lo.data(), hi.data(), nullptr),
              MUFRIC_OK);
    mufric_close(c);
  }
  EXPECT_EQ(client::server_status("grpc://" + server.address()).fast_points, 80) << "the C ABI's default uses it once";
}

// The extrapolation policy crosses the wire: refuse gives OUT_OF_BOX and NaN, counted in the
// response; the C ABI takes it as an option and names a bad one.
TEST_F(Service, ExtrapolationPolicyIsChosenPerRequest) {
  LoopbackServer server(dir_);
  Points pts = random_points(4);
  pts.p[1] = 5000e6;  // far above the box
  const std::string uri = "grpc://" + server.address() + "/gp";
  const auto client = client::connect(uri);
  EvaluationRequest refuse;
  refuse.extrapolation = Extrapolation::refuse;
  const client::Answer refused = client->evaluate(pts.block(), refuse);
  EXPECT_EQ(refused.status[1], PointStatus::out_of_box);
  EXPECT_TRUE(std::isnan(refused.mu[1]));
  EXPECT_EQ(refused.status[0], PointStatus::ok);
  const client::Answer clamped = client->evaluate(pts.block(), {});
  EXPECT_EQ(clamped.status[1], PointStatus::extrapolated);
  Points face = pts;
  face.p[1] = 1300e6;  // the box's top: where clamp evaluates
  EXPECT_EQ(clamped.mu[1], client->evaluate(face.block(), {}).mu[1]);

  mufric_client* c = nullptr;
  ASSERT_EQ(mufric_open_with_options(uri.c_str(), "extrapolation=refuse", &c), MUFRIC_OK) << mufric_last_error();
  std::vector<double> mu(4);
  std::vector<int> status(4);
  ASSERT_EQ(mufric_evaluate(c, 4, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, 0.0, mu.data(), nullptr, nullptr,
                            nullptr, status.data()),
            MUFRIC_PARTIAL);  // point 1 refused, the others answered
  EXPECT_EQ(status[1], MUFRIC_POINT_OUT_OF_BOX);
  mufric_close(c);
  EXPECT_EQ(mufric_open_with_options(uri.c_str(), "extrapolation=nearest", &c), MUFRIC_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mufric_last_error()).find("extrapolation"), std::string::npos) << mufric_last_error();
}

// The C ABI's options reach the connection: the token authorises, stream=1 sends every evaluation
// over one stream (the server counts the streams opened), and a misspelt key is refused by name.
// (A deadline cannot be shown to bite on loopback without a slow model: a 1 µs call sometimes
// completes; parse_options is checked above and the C++ client's deadlines in their own tests.)
// A calibrated model (issue 51) answers every interface with the same bits — in-process from its
// file, unary gRPC, the stream and the C ABI — and DescribeModel carries what it was calibrated on
// and its interval's parts (a campaign over p, v, T and a shear factor m; measurements at m = 0.5).
TEST_F(Service, ACalibratedModelAnswersEveryInterfaceAndDescribesItsCalibration) {
  auto simulator = [](const Eigen::RowVector4d& x) {  // fixed size: GCC 12 saw a null data pointer in a dynamic one
    const double ps = (x(0) - 300e6) / 1000e6, vs = (x(1) - 0.375) / 2.958, ts = (x(2) - 298.15) / 875.0;
    return 0.1 + 0.5 * x(3) * (1.0 - 0.3 * ps) - 0.05 * vs - 0.03 * ts;
  };
  TrainingSet campaign;
  campaign.inputs = default_friction_box();
  campaign.inputs.push_back({"shear_factor", "1", 0.2, 0.9});
  const Eigen::Index n = 60;
  campaign.x.resize(n, 4);
  campaign.mu.resize(n);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index k = 0; k < 4; ++k) {
      const InputSpec& in = campaign.inputs[static_cast<size_t>(k)];
      campaign.x(i, k) = in.lo + (in.hi - in.lo) * unit(rng);
    }
    campaign.mu(i) = simulator(campaign.x.row(i));
  }
  GpTrainingOptions options;
  options.restarts = 1;
  options.threads = 1;
  const auto emulator = std::make_shared<const GaussianProcess>(train_gaussian_process(campaign, options));
  Measurements data;
  data.condition_names = {"contact_pressure", "sliding_velocity", "temperature"};
  data.conditions.resize(6, 3);
  data.mu.resize(6);
  data.mu_sd = Eigen::VectorXd::Constant(6, 0.01);
  for (Eigen::Index i = 0; i < 6; ++i) {
    Eigen::RowVectorXd x(4);
    x << 400e6 + 150e6 * static_cast<double>(i), 0.5 + 0.4 * static_cast<double>(i), 400.0 + 100.0 * static_cast<double>(i), 0.5;
    data.conditions.row(i) = x.head(3);
    data.mu(i) = simulator(x);
    data.row_names.push_back("row " + std::to_string(i + 1));
  }
  // Two data sets, the second with a bias of its own, and three temperatures known within 30 K
  // (issue 60): what the posterior samples of such a model hold must reach every client alike.
  data.condition_sd = Eigen::MatrixXd::Zero(6, 3);
  for (const Eigen::Index i : {0, 2, 4}) data.condition_sd(i, 2) = 30.0;
  data.data_sets = {"cut", "tribometer"};
  data.data_set_of_row = {0, 0, 0, 1, 1, 1};
  CalibrationPriors priors;
  priors.biases.emplace_back("tribometer", Prior{PriorKind::normal, 0.0, 0.05});
  const CalibrationProblem problem(emulator, data, {"shear_factor"}, priors);
  ASSERT_EQ(problem.dimension(), 5);
  EnsembleOptions sampler;
  sampler.walkers = 12;
  sampler.burn_in_steps = 200;
  sampler.steps = 400;
  const CalibrationResult result = calibrate(problem, sampler);
  CalibrationRecord record;
  record.data_source = "six synthetic rows";
  record.posterior = result.summary;
  save_model((dir_ / "calibrated.h5").string(),
             CalibratedModel(std::make_shared<const CalibratedPosterior>(std::make_shared<const CalibrationProblem>(problem), result.samples),
                             record));
  // A second calibrated model in the folder at start: it is checked in a child forked after the first
  // was loaded (and its OpenMP team started) in the server's process (issue 63).
  std::filesystem::copy_file(dir_ / "calibrated.h5", dir_ / "calibrated_copy.h5");

  LoopbackServer server(dir_);
  const Points pts = random_points(200);
  EvaluationRequest what{.std = true, .ci_level = 0.95};
  const client::Answer local = client::connect("file://" + (dir_ / "calibrated.h5").string())->evaluate(pts.block(), what);
  ASSERT_EQ(local.mu.size(), 200u);
  for (const bool stream : {false, true}) {
    client::Options o;
    o.streaming = stream;
    o.chunk_points = 128;
    const client::Answer a = client::connect("grpc://" + server.address() + "/calibrated", o)->evaluate(pts.block(), what);
    EXPECT_EQ(a.mu, local.mu) << "stream " << stream;
    EXPECT_EQ(a.std, local.std);
    EXPECT_EQ(a.hi, local.hi);
  }
  EXPECT_EQ(client::connect("grpc://" + server.address() + "/calibrated_copy")->evaluate(pts.block(), what).mu, local.mu);
  mufric_client* c = nullptr;
  ASSERT_EQ(mufric_open(("grpc://" + server.address() + "/calibrated").c_str(), &c), MUFRIC_OK) << mufric_last_error();
  std::vector<double> mu(200);
  ASSERT_EQ(mufric_evaluate(c, 200, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, 0.95, mu.data(), nullptr, nullptr, nullptr,
                            nullptr),
            MUFRIC_OK)
      << mufric_last_error();
  EXPECT_EQ(mu, local.mu);
  mufric_close(c);

  auto stub = mufric::v1::FrictionService::NewStub(grpc::CreateChannel(server.address(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  mufric::v1::DescribeModelRequest request;
  request.set_model("calibrated");
  mufric::v1::ModelDescription d;
  ASSERT_TRUE(stub->DescribeModel(&context, request, &d).ok());
  EXPECT_EQ(d.kind(), "calibrated");
  EXPECT_EQ(d.interval(), "calibrated");
  EXPECT_EQ(d.inputs_size(), 3);
  ASSERT_TRUE(d.has_calibration());
  EXPECT_EQ(d.calibration().data_source(), "six synthetic rows");
  EXPECT_EQ(d.calibration().measurements(), 6u);
  // Every posterior coordinate, SI: the coefficient, the tribometer's bias, the three temperatures.
  ASSERT_EQ(d.calibration().parameters_size(), 5);
  EXPECT_EQ(d.calibration().parameters(0).name(), "shear_factor");
  EXPECT_EQ(d.calibration().parameters(1).name(), "bias[tribometer]");
  EXPECT_EQ(d.calibration().parameters(2).name(), "temperature (row 1)");
  EXPECT_LE(d.calibration().parameters(0).lo95(), 0.5);
  EXPECT_GE(d.calibration().parameters(0).hi95(), 0.5);
  const auto& parts = d.calibration().at_box_centre();
  EXPECT_NEAR(parts.sd() * parts.sd(), parts.parameter_sd() * parts.parameter_sd() + parts.conditional_sd() * parts.conditional_sd(),
              1e-12);
  EXPECT_GT(parts.parameter_sd(), 0.0);
  // The C++ client's ModelInfo carries the same, structured, in-process and over gRPC.
  for (const std::string& uri : std::vector<std::string>{"file://" + (dir_ / "calibrated.h5").string(), "grpc://" + server.address() + "/calibrated"}) {
    const client::ModelInfo info = client::connect(uri)->describe();
    ASSERT_TRUE(info.calibration.has_value()) << uri;
    ASSERT_EQ(info.calibration->parameters.size(), 5u) << uri;
    EXPECT_EQ(info.calibration->parameters[1].name, "bias[tribometer]") << uri;
    EXPECT_EQ(info.calibration->parameters[0].lo95, d.calibration().parameters(0).lo95()) << uri;
    EXPECT_EQ(info.calibration->at_box_centre.sd, parts.sd()) << uri;
    EXPECT_EQ(info.calibration->measurements, 6) << uri;
  }
  EXPECT_FALSE(client::connect("grpc://" + server.address() + "/gp")->describe().calibration.has_value());
  // A GP's description carries none.
  grpc::ClientContext gp_context;
  request.set_model("gp");
  ASSERT_TRUE(stub->DescribeModel(&gp_context, request, &d).ok());
  EXPECT_FALSE(d.has_calibration());
}

// The patch scatter (issue 33) of a model trained by stochastic kriging reaches every interface with
// the same bits: in-process, unary gRPC, the stream and the C ABI; DescribeModel says the model has
// one and what its interval is; a model without one refuses the C call and sends none.
TEST_F(Service, ThePatchScatterReachesEveryInterface) {
  TrainingSet t = test::smooth_training_set(40, 8);
  t.draws = DrawDesign::independent;
  t.draw_mu.resize(40, 4);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (Eigen::Index i = 0; i < 40; ++i) {
    const double spread = 0.01 + 0.02 * (t.x(i, 0) - t.inputs[0].lo) / (t.inputs[0].hi - t.inputs[0].lo);
    for (Eigen::Index k = 0; k < 4; ++k) t.draw_mu(i, k) = t.mu(i) + spread * normal(rng);
    t.mu(i) = t.draw_mu.row(i).mean();
  }
  GpTrainingOptions options;
  options.restarts = 1;
  const GaussianProcess sk = train_stochastic_kriging(t, options);
  save_model((dir_ / "sk.h5").string(), sk);
  LoopbackServer server(dir_);
  const Points pts = random_points(300);
  Points outside = pts;
  outside.p[7] = 5e9;  // above the box: the nearest face's patch scatter under clamp
  EvaluationRequest what{.std = true, .ci_level = 0.95, .patch_std = true};
  const client::Answer local = client::connect("file://" + (dir_ / "sk.h5").string())->evaluate(outside.block(), what);
  ASSERT_EQ(local.patch_std.size(), 300u);
  QueryBatch x(300, 3);
  for (Eigen::Index i = 0; i < 300; ++i) x.row(i) << outside.p[static_cast<size_t>(i)], outside.v[static_cast<size_t>(i)], outside.t[static_cast<size_t>(i)];
  const Eigen::VectorXd direct = sk.patch_std(x);
  for (size_t i = 0; i < 300; ++i) EXPECT_EQ(local.patch_std[i], direct(static_cast<Eigen::Index>(i))) << i;
  QueryBatch face = x.row(7);
  face(0, 0) = t.inputs[0].hi;
  EXPECT_EQ(local.patch_std[7], sk.patch_std(face)(0));
  for (const bool stream : {false, true}) {
    client::Options o;
    o.streaming = stream;
    o.chunk_points = 128;
    const auto remote = client::connect("grpc://" + server.address() + "/sk", o);
    EXPECT_TRUE(remote->describe().has_patch_scatter);
    const client::Answer a = remote->evaluate(outside.block(), what);
    EXPECT_EQ(a.patch_std, local.patch_std) << "stream " << stream;
    EXPECT_EQ(a.hi, local.hi);
  }
  // A model without one: nothing asked of it is sent back, and the C call is refused.
  const client::Answer plain = client::connect("grpc://" + server.address() + "/gp")->evaluate(pts.block(), what);
  EXPECT_TRUE(plain.patch_std.empty());
  EXPECT_FALSE(client::connect("grpc://" + server.address() + "/gp")->describe().has_patch_scatter);
  for (const std::string& uri : {"grpc://" + server.address() + "/sk", "file://" + (dir_ / "sk.h5").string()}) {
    mufric_client* c = nullptr;
    ASSERT_EQ(mufric_open_with_options(uri.c_str(), "fill=-1", &c), MUFRIC_OK) << mufric_last_error();
    EXPECT_EQ(mufric_has_patch_scatter(c), 1);
    std::vector<double> out(300);
    std::vector<int> status(300);
    Points bad = outside;
    bad.t[9] = -1.0;  // no answer: the fill value
    ASSERT_EQ(mufric_patch_std(c, 300, bad.p.data(), bad.v.data(), bad.t.data(), nullptr, out.data(), status.data()),
              MUFRIC_PARTIAL)
        << mufric_last_error();
    EXPECT_EQ(out[9], -1.0);
    EXPECT_EQ(status[9], MUFRIC_POINT_INVALID_INPUT);
    EXPECT_EQ(out[8], local.patch_std[8]) << uri;
    // One call for mu, its interval and the patch scatter gives what the separate calls give.
    std::vector<double> mu(300), lo(300), hi(300), together(300), mu_alone(300), lo_alone(300), hi_alone(300);
    mufric_outputs outputs{};
    outputs.mu = mu.data(), outputs.lo = lo.data(), outputs.hi = hi.data(), outputs.patch_std = together.data();
    ASSERT_EQ(mufric_evaluate_outputs(c, 300, bad.p.data(), bad.v.data(), bad.t.data(), nullptr, 0.95, &outputs),
              MUFRIC_PARTIAL)
        << mufric_last_error();
    ASSERT_EQ(mufric_evaluate(c, 300, bad.p.data(), bad.v.data(), bad.t.data(), nullptr, 0.95, mu_alone.data(), nullptr,
                              lo_alone.data(), hi_alone.data(), nullptr),
              MUFRIC_PARTIAL);
    EXPECT_EQ(together, out) << uri;
    EXPECT_EQ(mu, mu_alone);
    EXPECT_EQ(lo, lo_alone);
    EXPECT_EQ(hi, hi_alone);
    mufric_close(c);
  }
  mufric_client* c = nullptr;
  ASSERT_EQ(mufric_open(("grpc://" + server.address() + "/gp").c_str(), &c), MUFRIC_OK);
  EXPECT_EQ(mufric_has_patch_scatter(c), 0);
  std::vector<double> out(1);
  EXPECT_EQ(mufric_patch_std(c, 1, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, out.data(), nullptr),
            MUFRIC_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mufric_last_error()).find("no patch scatter"), std::string::npos) << mufric_last_error();
  mufric_close(c);
}

// Regression: under extrapolation=refuse every call returned MUFRIC_OK, with mu NaN or the fill
// value (fill=-1 reversed the friction force of an SPH code at 3853 points); n = 0 with NULL arrays
// was an error; the messages of mufric_evaluate_ex named mufric_evaluate.
TEST_F(Service, CAbiSaysWhenPointsWereNotAnsweredAndTakesAFallbackMu) {
  LoopbackServer server(dir_);
  Points pts = random_points(6);
  pts.p[2] = 5e9;   // above the box, a possible pressure: refused
  pts.t[4] = -3.0;  // impossible: invalid
  for (const std::string& uri : {"grpc://" + server.address() + "/gp", "file://" + (dir_ / "gp.h5").string()}) {
    mufric_client* c = nullptr;
    ASSERT_EQ(mufric_open_with_options(uri.c_str(), "extrapolation=refuse, fill=-1, fallback_mu=0.35", &c), MUFRIC_OK)
        << mufric_last_error();
    std::vector<double> mu(6), sd(6);
    std::vector<int> status(6);
    EXPECT_EQ(mufric_evaluate(c, 6, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, 0.0, mu.data(), sd.data(), nullptr,
                              nullptr, status.data()),
              MUFRIC_PARTIAL)
        << uri;
    EXPECT_NE(std::string(mufric_last_error()).find("point 2 OUT_OF_BOX"), std::string::npos) << mufric_last_error();
    EXPECT_EQ(status[2], MUFRIC_POINT_OUT_OF_BOX);
    EXPECT_EQ(status[4], MUFRIC_POINT_INVALID_INPUT);
    EXPECT_EQ(mu[2], 0.35);  // the caller's fallback, not the fill
    EXPECT_EQ(mu[4], 0.35);
    EXPECT_EQ(sd[2], -1.0);  // the fill where no fallback applies
    EXPECT_GT(mu[0], 0.0);
    EXPECT_EQ(status[0], MUFRIC_POINT_OK);
    // Every point answered: MUFRIC_OK and no message.
    EXPECT_EQ(mufric_evaluate(c, 2, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, 0.0, mu.data(), nullptr, nullptr,
                              nullptr, nullptr),
              MUFRIC_OK);
    EXPECT_STREQ(mufric_last_error(), "");
    // A step without contact: n = 0 with NULL arrays is a no-op.
    mufric_counts counts{};
    counts.invalid = 99;
    EXPECT_EQ(mufric_evaluate(c, 0, nullptr, nullptr, nullptr, nullptr, 0.0, nullptr, nullptr, nullptr, nullptr, nullptr),
              MUFRIC_OK)
        << mufric_last_error();
    EXPECT_EQ(mufric_evaluate_ex(c, 0, nullptr, nullptr, nullptr, nullptr, 0.0, nullptr, nullptr, nullptr, nullptr,
                                 nullptr, nullptr, &counts),
              MUFRIC_OK);
    EXPECT_EQ(counts.invalid, 0u);
    // A message names the function called.
    EXPECT_EQ(mufric_evaluate_ex(c, 2, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, 0.0, nullptr, nullptr,
                                 nullptr, nullptr, nullptr, nullptr, nullptr),
              MUFRIC_INVALID_ARGUMENT);
    EXPECT_STREQ(mufric_last_error(), "mufric_evaluate_ex: mu must not be NULL");
    EXPECT_EQ(mufric_evaluate_outputs(c, 2, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, 0.0, nullptr),
              MUFRIC_INVALID_ARGUMENT);
    EXPECT_STREQ(mufric_last_error(), "mufric_evaluate_outputs: outputs must not be NULL");
    mufric_close(c);
  }
  mufric_client* c = nullptr;
  EXPECT_EQ(mufric_open_with_options("grpc://127.0.0.1:1/gp", "fallback_mu=-1", &c), MUFRIC_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mufric_last_error()).find("fallback_mu"), std::string::npos) << mufric_last_error();
}

TEST_F(Service, CAbiOptionsReachTheConnection) {
  LoopbackServer server(dir_, 0, {.max_points_per_request = 1000000, .bearer_token = "s3cret"});
  const std::string uri = "grpc://" + server.address() + "/coulomb";
  mufric_client* c = nullptr;
  EXPECT_EQ(mufric_open_with_options(uri.c_str(), "retries=0", &c), MUFRIC_FAILED);
  EXPECT_NE(std::string(mufric_last_error()).find("UNAUTHENTICATED"), std::string::npos) << mufric_last_error();
  EXPECT_EQ(mufric_open_with_options(uri.c_str(), "token=s3cret, deadlin=2", &c), MUFRIC_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mufric_last_error()).find("'deadlin' is unknown"), std::string::npos) << mufric_last_error();

  const Points pts = random_points(5);
  std::vector<double> mu(5);
  for (const char* options : {"token=s3cret", "token=s3cret stream=1"}) {
    ASSERT_EQ(mufric_open_with_options(uri.c_str(), options, &c), MUFRIC_OK) << mufric_last_error();
    for (int increment = 0; increment < 3; ++increment) {
      ASSERT_EQ(mufric_evaluate(c, 5, pts.p.data(), pts.v.data(), pts.t.data(), nullptr, 0.0, mu.data(), nullptr,
                                nullptr, nullptr, nullptr),
                MUFRIC_OK)
          << mufric_last_error();
      EXPECT_EQ(mu[4], 0.3);
    }
    mufric_close(c);
  }
  client::Options authorised;
  authorised.token = "s3cret";
  EXPECT_EQ(client::server_status("grpc://" + server.address(), authorised).streams, 1)
      << "stream=1 opens one stream for its three increments";
}

}  // namespace
}  // namespace mufric
