#include "surrogate/core/friction_model.hpp"

#include <boost/math/distributions/normal.hpp>
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.hpp"

namespace mufric {
namespace {

// The one physical-range table of common/units.hpp: a negative pressure, speed or absolute
// temperature, or one beyond any physical value, is not a point of any model.
bool physically_valid(const InputSpec& input, double value) {
  return physical_range_violation(value, input.kind()).empty();
}

// An angle is periodic (a ply at θ and θ + 180° is the same ply): the laws wrap it, so the clamp
// policy leaves it as given.
bool clamped_input(const InputSpec& input) { return input.kind() != QuantityKind::angle; }

}  // namespace

std::string_view to_string(PointStatus status) {
  switch (status) {
    case PointStatus::ok: return "OK";
    case PointStatus::extrapolated: return "EXTRAPOLATED";
    case PointStatus::invalid_input: return "INVALID_INPUT";
    case PointStatus::out_of_box: return "OUT_OF_BOX";
  }
  return "UNKNOWN";
}

std::string_view to_string(Extrapolation policy) {
  switch (policy) {
    case Extrapolation::model_default: return "model default";
    case Extrapolation::raw: return "raw";
    case Extrapolation::clamp: return "clamp";
    case Extrapolation::refuse: return "refuse";
  }
  return "unknown";
}

Extrapolation extrapolation_from_string(std::string_view word) {
  if (word == "raw") return Extrapolation::raw;
  if (word == "clamp") return Extrapolation::clamp;
  if (word == "refuse") return Extrapolation::refuse;
  throw Error("extrapolation policy '" + std::string(word) + "' is unknown (raw, clamp or refuse)");
}

void FrictionModel::set_default_extrapolation(Extrapolation policy) {
  if (policy == Extrapolation::model_default) throw Error("a model's default extrapolation must be raw, clamp or refuse");
  default_extrapolation_ = policy;
}

void FrictionModel::set_mu_range(double lo, double hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) {
    throw Error("mu range [" + std::to_string(lo) + ", " + std::to_string(hi) + "] must be finite with lo < hi");
  }
  mu_min_ = lo;
  mu_max_ = hi;
}

double normal_quantile_two_sided(double level) {
  if (!(level > 0.0 && level < 1.0)) {
    throw Error("confidence level " + std::to_string(level) + " must lie strictly between 0 and 1");
  }
  return boost::math::quantile(boost::math::normal(), 0.5 * (1.0 + level));
}

// Under the clamp policy μ is the box face's, but nothing is known beyond the face: σ is the model's
// own root-mean-square error of that answer at the real point, E[(f(x) − μ_face)²] = σ²(x) + (μ(x) −
// μ_face)² under the model's posterior at x (the raw model: a GP reverts to its prior there). It
// equals the face's σ at the face and grows with the distance from the box; it is never below the
// raw model's σ (issue 30: clamping it gave 0.023 at 10 GPa, the value at the 1.3 GPa face).
void FrictionModel::widen_clamped_intervals(const QueryBatch& x, const std::vector<Eigen::Index>& valid,
                                            const EvaluationRequest& what, Evaluation& clamped) const {
  std::vector<Eigen::Index> outside;  // positions in `valid`
  for (size_t k = 0; k < valid.size(); ++k) {
    for (size_t j = 0; j < inputs_.size(); ++j) {
      if (clamped_input(inputs_[j]) && !inputs_[j].contains(x(valid[k], static_cast<Eigen::Index>(j)))) {
        outside.push_back(static_cast<Eigen::Index>(k));
        break;
      }
    }
  }
  if (outside.empty()) return;
  QueryBatch real(static_cast<Eigen::Index>(outside.size()), x.cols());
  for (size_t r = 0; r < outside.size(); ++r) real.row(static_cast<Eigen::Index>(r)) = x.row(valid[static_cast<size_t>(outside[r])]);
  EvaluationRequest raw_what{.std = true, .max_threads = what.max_threads};
  raw_what.mu_tolerance = what.mu_tolerance;
  raw_what.std_relative_tolerance = what.std_relative_tolerance;
  Evaluation raw;
  evaluate_valid(real, raw_what, raw);
  for (size_t r = 0; r < outside.size(); ++r) {
    const Eigen::Index k = outside[r];
    const auto i = static_cast<Eigen::Index>(r);
    clamped.std(k) = std::hypot(raw.std(i), clamped.mu(k) - raw.mu(i));
  }
  clamped.clamped_variances += raw.clamped_variances;
}

Eigen::VectorXd FrictionModel::patch_std_valid(const QueryBatch& x, const EvaluationRequest&) const {
  return Eigen::VectorXd::Constant(x.rows(), std::numeric_limits<double>::quiet_NaN());
}

Evaluation FrictionModel::evaluate(const QueryBatch& x, const EvaluationRequest& what) const {
  const auto d = static_cast<Eigen::Index>(inputs_.size());
  if (x.cols() != d) {
    throw Error("query has " + std::to_string(x.cols()) + " inputs, the model expects " + std::to_string(d));
  }
  const double z = what.ci_level > 0.0 ? normal_quantile_two_sided(what.ci_level) : 0.0;
  const Extrapolation policy = effective_extrapolation(what.extrapolation, default_extrapolation_);
  const Eigen::Index m = x.rows();
  Evaluation out;
  out.status.assign(static_cast<size_t>(m), PointStatus::ok);
  std::vector<Eigen::Index> valid;
  valid.reserve(static_cast<size_t>(m));
  bool any_outside = false;
  for (Eigen::Index i = 0; i < m; ++i) {
    PointStatus& status = out.status[static_cast<size_t>(i)];
    for (Eigen::Index j = 0; j < d; ++j) {
      const InputSpec& input = inputs_[static_cast<size_t>(j)];
      if (!physically_valid(input, x(i, j))) {
        status = PointStatus::invalid_input;
        break;
      }
      if (!input.contains(x(i, j))) status = policy == Extrapolation::refuse ? PointStatus::out_of_box : PointStatus::extrapolated;
    }
    if (has_no_answer(status)) continue;
    any_outside = any_outside || status == PointStatus::extrapolated;
    valid.push_back(i);
  }

  const bool need_std = what.std || what.ci_level > 0.0;
  const auto n_valid = static_cast<Eigen::Index>(valid.size());
  const bool clamp = policy == Extrapolation::clamp && any_outside;
  Evaluation inner;
  const bool patch = what.patch_std && has_patch_scatter();
  if (n_valid == m && !clamp) {
    evaluate_valid(x, what, inner);
    if (patch) inner.patch_std = patch_std_valid(x, what);
  } else if (n_valid > 0) {
    QueryBatch compact(n_valid, d);
    for (Eigen::Index k = 0; k < n_valid; ++k) compact.row(k) = x.row(valid[static_cast<size_t>(k)]);
    if (clamp) {
      for (Eigen::Index j = 0; j < d; ++j) {
        const InputSpec& input = inputs_[static_cast<size_t>(j)];
        if (clamped_input(input)) compact.col(j) = compact.col(j).cwiseMax(input.lo).cwiseMin(input.hi);
      }
    }
    evaluate_valid(compact, what, inner);
    if (patch) inner.patch_std = patch_std_valid(compact, what);  // the face's, for a clamped point
    if (clamp && need_std && has_uncertainty()) widen_clamped_intervals(x, valid, what, inner);
    if (clamp && what.gradient) {
      // μ is constant along a clamped input beyond the box.
      for (Eigen::Index k = 0; k < n_valid; ++k) {
        for (Eigen::Index j = 0; j < d; ++j) {
          const InputSpec& input = inputs_[static_cast<size_t>(j)];
          if (clamped_input(input) && !input.contains(x(valid[static_cast<size_t>(k)], j))) inner.gradient(k, j) = 0.0;
        }
      }
    }
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
    if (patch) out.patch_std = std::move(inner.patch_std);
  } else {
    scatter(inner.mu, out.mu);
    if (need_std) scatter(inner.std, out.std);
    if (patch) scatter(n_valid > 0 ? inner.patch_std : Eigen::VectorXd(), out.patch_std);
    if (what.gradient) {
      out.gradient.setConstant(m, d, nan);
      for (Eigen::Index k = 0; k < n_valid; ++k) out.gradient.row(valid[static_cast<size_t>(k)]) = inner.gradient.row(k);
    }
  }
  if (what.ci_level > 0.0) {
    out.lo = out.mu - z * out.std;
    out.hi = out.mu + z * out.std;
  }
  // The model's physical range of μ; points without an answer (NaN) stay without.
  for (Eigen::Index i = 0; i < m; ++i) {
    if (std::isnan(out.mu(i))) continue;
    bool clipped = out.mu(i) < mu_min_ || out.mu(i) > mu_max_;
    out.mu(i) = std::clamp(out.mu(i), mu_min_, mu_max_);
    if (what.ci_level > 0.0) {
      clipped = clipped || out.lo(i) < mu_min_ || out.hi(i) > mu_max_;
      out.lo(i) = std::clamp(out.lo(i), mu_min_, mu_max_);
      out.hi(i) = std::clamp(out.hi(i), mu_min_, mu_max_);
    }
    out.range_clipped += clipped;
  }
  if (!what.std && what.ci_level > 0.0) out.std.resize(0);
  out.clamped_variances = inner.clamped_variances;
  out.fast_points = inner.fast_points;
  return out;
}

std::string point_reason(const InputSpace& inputs, const double* x) {
  // Every input at fault, not the first: a user fixing one would otherwise meet the next one later.
  std::string reasons;
  const auto add = [&reasons](const std::string& reason) { reasons += (reasons.empty() ? "" : "; ") + reason; };
  for (size_t j = 0; j < inputs.size(); ++j) {
    const std::string why = physical_range_violation(x[j], inputs[j].kind());
    if (!why.empty()) add(inputs[j].name + ": " + why);
  }
  if (!reasons.empty()) return reasons;
  for (size_t j = 0; j < inputs.size(); ++j) {
    if (inputs[j].contains(x[j])) continue;
    const QuantityKind kind = inputs[j].kind();
    add(inputs[j].name + ": " + format_human(x[j], kind) + " is " + (x[j] < inputs[j].lo ? "below" : "above") +
        " the box (" + format_human(inputs[j].lo, kind) + " to " + format_human(inputs[j].hi, kind) + ")");
  }
  return reasons;
}

std::string more_points_tail(long long more, bool extrapolated) {
  if (more <= 0) return {};
  return " (and " + std::to_string(more) + (more == 1 ? " more point " : " more points ") +
         (extrapolated ? "outside the box)" : "without an answer)");
}

std::string clamped_face_text(const InputSpace& inputs, const double* x) {
  std::string at;
  for (size_t j = 0; j < inputs.size(); ++j) {
    if (!clamped_input(inputs[j]) || inputs[j].contains(x[j])) continue;
    const double face = x[j] < inputs[j].lo ? inputs[j].lo : inputs[j].hi;
    at += (at.empty() ? "" : ", ") + inputs[j].name + " = " + format_human(face, inputs[j].kind());
  }
  return at;
}

std::string block_message(const InputSpace& inputs, const QueryBatch& x, const std::vector<PointStatus>& status,
                          Extrapolation policy) {
  std::string message = unanswered_points_message(inputs, x, status);
  return message.empty() ? extrapolated_points_message(inputs, x, status, policy) : message;
}

std::string extrapolated_points_message(const InputSpace& inputs, const QueryBatch& x, const std::vector<PointStatus>& status,
                                        Extrapolation policy) {
  long long outside = 0;
  std::string first;
  for (size_t i = 0; i < status.size(); ++i) {
    if (status[i] != PointStatus::extrapolated) continue;
    if (outside++ > 0) continue;
    const Eigen::RowVectorXd row = x.row(static_cast<Eigen::Index>(i));
    first = "point " + std::to_string(i) + " EXTRAPOLATED: " + point_reason(inputs, row.data()) + "; answered ";
    if (policy == Extrapolation::clamp) {
      first += "at " + clamped_face_text(inputs, row.data()) + " (clamp)";
    } else {
      first += "by the raw model beyond its data (raw)";
    }
  }
  first += more_points_tail(outside - 1, true);
  return first;
}

std::string unanswered_points_message(const InputSpace& inputs, const QueryBatch& x, const std::vector<PointStatus>& status) {
  long long unanswered = 0;
  std::string first;
  for (size_t i = 0; i < status.size(); ++i) {
    if (!has_no_answer(status[i])) continue;
    if (unanswered++ == 0) {
      const Eigen::RowVectorXd row = x.row(static_cast<Eigen::Index>(i));
      first = "point " + std::to_string(i) + " " + std::string(to_string(status[i])) + ": " + point_reason(inputs, row.data());
    }
  }
  first += more_points_tail(unanswered - 1, false);
  return first;
}

}  // namespace mufric
