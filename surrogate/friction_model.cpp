#include "surrogate/friction_model.hpp"

#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>

#include "common/error.hpp"

namespace mufric {
namespace {

// Pressure, speed and absolute temperature are non-negative by nature; angles and unnamed inputs are free.
bool physically_valid(const InputSpec& input, double value) {
  if (!std::isfinite(value)) return false;
  switch (input.kind()) {
    case QuantityKind::pressure:
    case QuantityKind::velocity:
    case QuantityKind::temperature: return value >= 0.0;
    default: return true;
  }
}

}  // namespace

std::string_view to_string(PointStatus status) {
  switch (status) {
    case PointStatus::ok: return "OK";
    case PointStatus::extrapolated: return "EXTRAPOLATED";
    case PointStatus::invalid_input: return "INVALID_INPUT";
  }
  return "UNKNOWN";
}

double normal_quantile_two_sided(double level) {
  if (!(level > 0.0 && level < 1.0)) {
    throw Error("confidence level " + std::to_string(level) + " must lie strictly between 0 and 1");
  }
  return boost::math::quantile(boost::math::normal(), 0.5 * (1.0 + level));
}

Evaluation FrictionModel::evaluate(const QueryBatch& x, const EvaluationRequest& what) const {
  const auto d = static_cast<Eigen::Index>(inputs_.size());
  if (x.cols() != d) {
    throw Error("query has " + std::to_string(x.cols()) + " inputs, the model expects " + std::to_string(d));
  }
  const double z = what.ci_level > 0.0 ? normal_quantile_two_sided(what.ci_level) : 0.0;
  const Eigen::Index m = x.rows();
  Evaluation out;
  out.status.assign(static_cast<size_t>(m), PointStatus::ok);
  std::vector<Eigen::Index> valid;
  valid.reserve(static_cast<size_t>(m));
  for (Eigen::Index i = 0; i < m; ++i) {
    PointStatus& status = out.status[static_cast<size_t>(i)];
    for (Eigen::Index j = 0; j < d; ++j) {
      const InputSpec& input = inputs_[static_cast<size_t>(j)];
      if (!physically_valid(input, x(i, j))) {
        status = PointStatus::invalid_input;
        break;
      }
      if (!input.contains(x(i, j))) status = PointStatus::extrapolated;
    }
    if (status != PointStatus::invalid_input) valid.push_back(i);
  }

  const bool need_std = what.std || what.ci_level > 0.0;
  const auto n_valid = static_cast<Eigen::Index>(valid.size());
  Evaluation inner;
  if (n_valid == m) {
    evaluate_valid(x, what, inner);
  } else if (n_valid > 0) {
    QueryBatch compact(n_valid, d);
    for (Eigen::Index k = 0; k < n_valid; ++k) compact.row(k) = x.row(valid[static_cast<size_t>(k)]);
    evaluate_valid(compact, what, inner);
  }

  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  auto scatter = [&](const Eigen::VectorXd& from, Eigen::VectorXd& to) {
    to.setConstant(m, nan);
    for (Eigen::Index k = 0; k < n_valid; ++k) to(valid[static_cast<size_t>(k)]) = from(k);
  };
  if (n_valid == m) {
    out.mu = std::move(inner.mu);
    if (need_std) out.std = std::move(inner.std);
    if (what.gradient) out.gradient = std::move(inner.gradient);
  } else {
    scatter(inner.mu, out.mu);
    if (need_std) scatter(inner.std, out.std);
    if (what.gradient) {
      out.gradient.setConstant(m, d, nan);
      for (Eigen::Index k = 0; k < n_valid; ++k) out.gradient.row(valid[static_cast<size_t>(k)]) = inner.gradient.row(k);
    }
  }
  if (what.ci_level > 0.0) {
    out.lo = out.mu - z * out.std;
    out.hi = out.mu + z * out.std;
  }
  if (!what.std && what.ci_level > 0.0) out.std.resize(0);
  out.clamped_variances = inner.clamped_variances;
  out.fast_points = inner.fast_points;
  return out;
}

}  // namespace mufric
