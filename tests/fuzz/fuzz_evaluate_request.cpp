// The server's request path after authorisation: protobuf bytes → EvaluateRequest → validation →
// evaluation by a served GP and a Coulomb law (FrictionService::evaluate, what Evaluate runs).
// Bytes that do not parse are what gRPC refuses before us. Every answer must be a status, and an OK
// answer must carry one mu and one status per point.
#include <cstdlib>
#include <filesystem>

#include "fuzz_support.hpp"
#include "server/friction_service.hpp"
#include "surrogate/laws/empirical_laws.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/models/model_file.hpp"

namespace {

struct Served {
  std::filesystem::path directory;
  std::unique_ptr<mufric::server::ModelRegistry> registry;
  std::unique_ptr<mufric::server::FrictionService> service;
  Served() {
    directory = std::filesystem::temp_directory_path() / ("mufric-fuzz-models-" + std::to_string(::getpid()));
    std::filesystem::create_directories(directory);
    mufric::TrainingSet t;
    t.inputs = {{"contact_pressure", "Pa", 3e8, 1.3e9},
                {"sliding_velocity", "m/s", 0.375, 3.333},
                {"temperature", "K", 298.15, 1173.15}};
    t.x.resize(12, 3);
    t.mu.resize(12);
    for (Eigen::Index i = 0; i < 12; ++i) {
      const double s = static_cast<double>(i) / 11.0;
      t.x.row(i) << 3e8 + 1e9 * s, 0.375 + 2.958 * (1 - s) * s * 4, 298.15 + 875 * s * s;
      t.mu(i) = 0.2 + 0.05 * s - 0.03 * s * s;
    }
    mufric::GpTrainingOptions options;
    options.optimise = false;
    mufric::save_model((directory / "gp.h5").string(), mufric::train_gaussian_process(t, options));
    mufric::save_model((directory / "coulomb.h5").string(), mufric::CoulombLaw(0.3));
    registry = std::make_unique<mufric::server::ModelRegistry>(directory, [](const std::string&, const std::string&) {});
    registry->refresh();
    mufric::server::ServiceLimits limits;
    limits.max_points_per_request = 4096;
    service = std::make_unique<mufric::server::FrictionService>(*registry, limits);
  }
  ~Served() { std::filesystem::remove_all(directory); }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Served served;
  mufric::v1::EvaluateRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  // Half of the inputs go to a model that exists, so the fuzzer need not guess its name.
  if (size > 0 && (data[0] & 1)) request.set_model((data[0] & 2) ? "gp" : "coulomb");
  mufric::v1::EvaluateResponse response;
  const grpc::Status status = served.service->evaluate(request, response);
  if (status.ok() && (response.mu_size() != response.status_size())) std::abort();
  return 0;
}
