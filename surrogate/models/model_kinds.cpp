#include "surrogate/models/model_kinds.hpp"

#include "common/registry.hpp"

#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/laws/empirical_laws.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {
namespace {

template <class Model>
std::function<std::unique_ptr<FrictionModel>(const h5::Reader&, InputSpace)> reader() {
  return [](const h5::Reader& in, InputSpace inputs) { return std::make_unique<Model>(Model::read(in, std::move(inputs))); };
}

}  // namespace

const std::vector<ModelKindEntry>& model_kinds() {
  static const std::vector<ModelKindEntry> kinds{
      {"gp", "a Gaussian process of a campaign (its fast evaluator and patch scatter optional)", reader<GaussianProcess>()},
      {"mlr", "seed 001's multi-linear regression per fibre angle, clamped", reader<MlrLaw>()},
      {"coulomb", "one constant friction coefficient", reader<CoulombLaw>()},
      {"calibrated", "the posterior predictive of a calibration through a campaign's GP", reader<CalibratedModel>()}};
  return kinds;
}

const ModelKindEntry* find_model_kind(std::string_view name) { return find_entry(model_kinds(), name); }

std::string model_kind_names() { return entry_names(model_kinds()); }

}  // namespace mufric
