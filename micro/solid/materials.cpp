#include "micro/solid/materials.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.hpp"
#include "micro/solid/dual.hpp"

namespace mufric::solid {
namespace {

const double kSqrtTwoThirds = std::sqrt(2.0 / 3.0);
// Below this ratio r/m of eigenvalue half-gap to mean, isotropic functions of a 2×2 symmetric
// matrix use their Taylor series in r² (exact to ~(r/m)⁶): no division by a vanishing gap.
constexpr double kIsotropicSeriesBelow = 1e-4;
// The return map's scalar equation is solved to this fraction of the trial stress norm.
constexpr double kReturnMapRelativeTolerance = 1e-13;
constexpr int kReturnMapMaxIterations = 200;
// A Newton update this small relative to Δγ is round-off: the root is found.
constexpr double kReturnMapStagnation = 1e-15;

template <class T>
struct Sym2 {
  T xx, xy, yy;
};

// f(A) for a symmetric 2×2 A with eigenvalues m ± r: f(A) = c0 I + c1 (A − m I) with
// c0 = (f(m+r) + f(m−r))/2 and c1 = (f(m+r) − f(m−r))/(2r), or their series in r² when r ≪ m.
// `f` evaluates f at a point, `taylor` returns f, f', …, f⁽⁵⁾ at m.
template <class T, class F, class Taylor>
Sym2<T> isotropic_function(const Sym2<T>& a, F f, Taylor taylor) {
  const T m = 0.5 * (a.xx + a.yy);
  const T dxx = a.xx - m;
  const T s = dxx * dxx + a.xy * a.xy;  // r²
  T c0, c1;
  if (value(s) <= kIsotropicSeriesBelow * kIsotropicSeriesBelow * value(m) * value(m)) {
    const auto d = taylor(m);
    c0 = d[0] + d[2] * s / 2.0 + d[4] * s * s / 24.0;
    c1 = d[1] + d[3] * s / 6.0 + d[5] * s * s / 120.0;
  } else {
    using std::sqrt;
    const T r = sqrt(s);
    const T fp = f(m + r), fm = f(m - r);
    c0 = 0.5 * (fp + fm);
    c1 = (fp - fm) / (2.0 * r);
  }
  return {c0 + c1 * dxx, c1 * a.xy, c0 - c1 * dxx};
}

template <class T>
Sym2<T> sym_log(const Sym2<T>& a) {
  using std::log;
  return isotropic_function(
      a, [](const T& x) { return T(log(x)); },
      [](const T& m) {
        const T i = 1.0 / m;
        return std::array<T, 6>{log(m), i, -1.0 * i * i, 2.0 * i * i * i, -6.0 * i * i * i * i, 24.0 * i * i * i * i * i};
      });
}

Sym2<double> sym_exp(const Sym2<double>& a) {
  return isotropic_function(
      a, [](double x) { return std::exp(x); },
      [](double m) {
        const double e = std::exp(m);
        return std::array<double, 6>{e, e, e, e, e, e};
      });
}

struct YieldWithSlope {
  double stress, slope;  // σy and dσy/dΔγ along the return map
};

double temperature_factor(const JohnsonCookParameters& p, double temperature) {
  const double hat = std::clamp((temperature - p.transition_temperature) /
                                    (p.melting_temperature - p.transition_temperature),
                                0.0, 1.0);
  return 1.0 - std::pow(hat, p.m);
}

// 1 + C ln(max(ε̇/ε̇0, 1)): the log term never lowers the yield stress below its ε̇0 value.
double rate_factor(const JohnsonCookParameters& p, double rate) {
  return 1.0 + p.c * std::log(std::max(rate / p.reference_strain_rate, 1.0));
}

// σy at ε̄ = ε̄n + √(2/3)Δγ and rate √(2/3)Δγ/dt, with its derivative in Δγ; `thermal` is the
// temperature factor (1 − θ̂^m), constant during a step.
YieldWithSlope yield_along_return(const JohnsonCookParameters& p, double start_strain, double dgamma, double dt,
                                  double thermal) {
  const double strain = start_strain + kSqrtTwoThirds * dgamma;
  const double rate = kSqrtTwoThirds * dgamma / dt;
  const double power = std::pow(strain, p.n);  // one pow: the slope is n·power/strain
  const double hardening = p.a + p.b * power;
  const double hardening_slope = strain > 0.0 ? p.b * p.n * power / strain : std::numeric_limits<double>::infinity();
  const double factor = rate_factor(p, rate);
  const double rate_slope = rate > p.reference_strain_rate ? p.c / rate : 0.0;  // d(rate factor)/d(rate)
  return {hardening * factor * thermal,
          thermal * kSqrtTwoThirds * (hardening_slope * factor + hardening * rate_slope / dt)};
}

}  // namespace

double johnson_cook_yield_stress(const JohnsonCookParameters& p, double plastic_strain, double plastic_strain_rate,
                                 double temperature) {
  return (p.a + p.b * std::pow(plastic_strain, p.n)) * rate_factor(p, plastic_strain_rate) *
         temperature_factor(p, temperature);
}

LinearElastic::LinearElastic(double youngs_modulus, double poisson_ratio, double density, PlaneKind kind)
    : density_(density) {
  if (!(youngs_modulus > 0.0) || !(poisson_ratio > -1.0 && poisson_ratio < 0.5)) {
    throw Error("linear elastic material: needs E > 0 and -1 < nu < 0.5");
  }
  mu_ = youngs_modulus / (2.0 * (1.0 + poisson_ratio));
  lambda_ = youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
  if (kind == PlaneKind::stress) lambda_ = 2.0 * lambda_ * mu_ / (lambda_ + 2.0 * mu_);
}

StressResponse LinearElastic::update(const Eigen::Matrix2d& h, const MaterialState& start, double, bool,
                                     const MaterialState*) const {
  StressResponse r;
  const Eigen::Matrix2d strain = 0.5 * (h + h.transpose());
  r.stress = lambda_ * strain.trace() * Eigen::Matrix2d::Identity() + 2.0 * mu_ * strain;
  r.tangent.setZero();
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      for (int k = 0; k < 2; ++k) {
        for (int l = 0; l < 2; ++l) {
          r.tangent(2 * i + j, 2 * k + l) =
              lambda_ * (i == j) * (k == l) + mu_ * ((i == k) * (j == l) + (i == l) * (j == k));
        }
      }
    }
  }
  r.state = start;
  return r;
}

double LinearElastic::energy_density(const Eigen::Matrix2d& h) const {
  const Eigen::Matrix2d strain = 0.5 * (h + h.transpose());
  return 0.5 * lambda_ * strain.trace() * strain.trace() + mu_ * strain.squaredNorm();
}

J2JohnsonCook::J2JohnsonCook(JohnsonCookParameters parameters) : p_(parameters) {
  if (!(p_.youngs_modulus > 0.0) || !(p_.poisson_ratio > -1.0 && p_.poisson_ratio < 0.5) || !(p_.density > 0.0) ||
      !(p_.a > 0.0) || !(p_.reference_strain_rate > 0.0) || !(p_.melting_temperature > p_.transition_temperature)) {
    throw Error("Johnson-Cook material: E, density, A, reference strain rate must be positive, -1 < nu < 0.5, "
                "and the melting temperature above the transition temperature");
  }
  mu_ = p_.youngs_modulus / (2.0 * (1.0 + p_.poisson_ratio));
  kappa_ = p_.youngs_modulus / (3.0 * (1.0 - 2.0 * p_.poisson_ratio));
}

namespace {

// The part of the update that the tangent differentiates: P(F) with Δγ known (converged in double).
template <class T>
struct KirchhoffTrial {
  Sym2<T> dev;  // deviatoric trial logarithmic elastic strain, in-plane
  T dev_zz;
  T volumetric;  // tr ε
  T norm;        // ‖dev ε‖
};

template <class T>
KirchhoffTrial<T> trial_strain(const Eigen::Matrix<T, 2, 2>& f, const MaterialState& s) {
  const auto& c = s.plastic_metric_inverse;
  // be = F Cp⁻¹ Fᵀ (in-plane block; out of plane F_zz = 1, so be_zz = Cp⁻¹_zz).
  Eigen::Matrix<T, 2, 2> cp;
  cp << T(c[0]), T(c[1]), T(c[1]), T(c[2]);
  const Eigen::Matrix<T, 2, 2> b = f * cp * f.transpose();
  const Sym2<T> eps = sym_log(Sym2<T>{b(0, 0), 0.5 * (b(0, 1) + b(1, 0)), b(1, 1)});
  const T eps_xx = 0.5 * eps.xx, eps_xy = 0.5 * eps.xy, eps_yy = 0.5 * eps.yy;
  const T eps_zz = T(0.5 * std::log(c[3]));
  KirchhoffTrial<T> t;
  t.volumetric = eps_xx + eps_yy + eps_zz;
  const T third = t.volumetric / 3.0;
  t.dev = {eps_xx - third, eps_xy, eps_yy - third};
  t.dev_zz = eps_zz - third;
  using std::sqrt;
  t.norm = sqrt(t.dev.xx * t.dev.xx + t.dev.yy * t.dev.yy + t.dev_zz * t.dev_zz + 2.0 * t.dev.xy * t.dev.xy + 1e-300);
  return t;
}

}  // namespace

StressResponse J2JohnsonCook::update(const Eigen::Matrix2d& h, const MaterialState& start, double dt,
                                     bool with_tangent, const MaterialState* iterate) const {
  StressResponse out;
  out.state = start;
  const Eigen::Matrix2d f = Eigen::Matrix2d::Identity() + h;
  const double jacobian = f.determinant();
  if (!(jacobian > 0.0)) {
    out.ok = false;
    out.reason = "deformation gradient with det F = " + std::to_string(jacobian) + " (inverted material)";
    out.stress.setZero();
    out.tangent.setZero();
    return out;
  }
  const Eigen::Matrix2d f_inv = f.inverse();
  const KirchhoffTrial<double> trial = trial_strain<double>(f, start);
  const double q_trial = 2.0 * mu_ * trial.norm;  // ‖dev τ_trial‖
  const double theta = start.temperature;
  const double thermal = temperature_factor(p_, theta);
  const double eps_n = start.equivalent_plastic_strain;
  // σy at the start of the step, at rest (the rate factor is 1 below ε̇0): one pow for hardening.
  const double yield_start = (p_.a + p_.b * std::pow(eps_n, p_.n)) * thermal;
  double dgamma = 0.0, slope = 0.0;
  YieldWithSlope yield_end{yield_start, 0.0};
  if (q_trial - kSqrtTwoThirds * yield_start > kReturnMapRelativeTolerance * q_trial) {
    // r(Δγ) = q − 2μΔγ − √(2/3) σy(Δγ), decreasing; r(0) > 0 ≥ r(q/2μ). Newton in x = ln Δγ, kept
    // in the bracket (rtsafe, Press et al., Numerical Recipes 3rd ed., sec. 9.4): in x, r is concave
    // (2μe^x is convex, and σy is a product of positive, increasing, convex factors — (ε̄n + ce^x)^n
    // and 1 + C max(x − x0, 0)), so from a start right of the root the iterates fall monotonically
    // onto it. Newton in Δγ itself overshot into the power and log singularities of σy at Δγ → 0 and
    // bisected: 11.4 iterations per plastic update on average, a third of them over 8 (default scene).
    double lo = 0.0, hi = q_trial / (2.0 * mu_);
    // The perfectly plastic answer (yield stress frozen at its start value) bounds the root from
    // above: hardening and rate only raise σy. In steady flow the last step's plastic strain rate
    // is a closer start (5.2 instead of 6.2 iterations, default scene); from a start left of the
    // root, concavity costs one overshoot to the right, then the same monotone descent.
    const double perfectly_plastic = std::clamp((q_trial - kSqrtTwoThirds * yield_start) / (2.0 * mu_), 0.01 * hi, 0.99 * hi);
    // Within a step's Newton iteration, the Δγ of the previous iterate is closer still.
    const double guess_rate = iterate != nullptr && iterate->plastic_strain_rate > 0.0 ? iterate->plastic_strain_rate
                                                                                       : start.plastic_strain_rate;
    const double at_guess = guess_rate * dt / kSqrtTwoThirds;
    dgamma = at_guess > 0.0 ? std::min(at_guess, perfectly_plastic) : perfectly_plastic;
    bool converged = false;
    for (int it = 0; it < kReturnMapMaxIterations; ++it) {
      const YieldWithSlope y = yield_along_return(p_, eps_n, dgamma, dt, thermal);
      const double r = q_trial - 2.0 * mu_ * dgamma - kSqrtTwoThirds * y.stress;
      slope = -2.0 * mu_ - kSqrtTwoThirds * y.slope;
      yield_end = y;
      if (std::abs(r) <= kReturnMapRelativeTolerance * q_trial) {
        converged = true;
        break;
      }
      (r > 0.0 ? lo : hi) = dgamma;
      double next = dgamma * std::exp(-r / (slope * dgamma));  // x − r/(dr/dx), dr/dx = Δγ dr/dΔγ
      if (!std::isfinite(next) || next <= lo || next >= hi) next = 0.5 * (lo + hi);
      if (hi - lo <= 1e-16 * q_trial / mu_ || std::abs(next - dgamma) <= kReturnMapStagnation * dgamma) {
        converged = true;
        break;
      }
      dgamma = next;
    }
    if (!converged) {
      out.ok = false;
      out.reason = "Johnson-Cook return map did not converge in " + std::to_string(kReturnMapMaxIterations) + " iterations";
      out.stress.setZero();
      out.tangent.setZero();
      return out;
    }
  }
  if (!std::isfinite(slope) || slope == 0.0) slope = -2.0 * mu_;  // elastic, or hardening slope unbounded

  if (with_tangent) {
    stress_and_tangent(f, start, dgamma, yield_end.stress, slope, out);
  } else {
    // The same stress in doubles: τ = 2μ dev ε (1 − 2μΔγ/q) + κ tr ε I, P = τ F⁻ᵀ.
    const double scale = dgamma > 0.0 ? 1.0 - 2.0 * mu_ * dgamma / q_trial : 1.0;
    const double pressure = kappa_ * trial.volumetric;
    Eigen::Matrix2d tau;
    tau << 2.0 * mu_ * trial.dev.xx * scale + pressure, 2.0 * mu_ * trial.dev.xy * scale,
        2.0 * mu_ * trial.dev.xy * scale, 2.0 * mu_ * trial.dev.yy * scale + pressure;
    out.stress = tau * f_inv.transpose();
  }

  if (dgamma == 0.0) {
    // Elastic: Cp⁻¹ and ε̄p stay as they were (the formulas below would return them up to round-off).
    out.state.plastic_strain_rate = 0.0;
    out.state.yield_stress = yield_start;
    return out;
  }
  // New state: εe = dev εtrial (1 − 2μΔγ/q) + tr/3 I; be = exp(2εe); Cp⁻¹ = F⁻¹ be F⁻ᵀ.
  const double keep = 1.0 - 2.0 * mu_ * dgamma / q_trial;
  const double third = trial.volumetric / 3.0;
  const Sym2<double> be = sym_exp(Sym2<double>{2.0 * (trial.dev.xx * keep + third), 2.0 * trial.dev.xy * keep,
                                               2.0 * (trial.dev.yy * keep + third)});
  Eigen::Matrix2d be_matrix;
  be_matrix << be.xx, be.xy, be.xy, be.yy;
  const Eigen::Matrix2d cp_inv = f_inv * be_matrix * f_inv.transpose();
  out.state.plastic_metric_inverse = {cp_inv(0, 0), 0.5 * (cp_inv(0, 1) + cp_inv(1, 0)), cp_inv(1, 1),
                                      std::exp(2.0 * (trial.dev_zz * keep + third))};
  const double d_eps = kSqrtTwoThirds * dgamma;
  out.state.equivalent_plastic_strain = eps_n + d_eps;
  out.state.plastic_strain_rate = d_eps / dt;
  out.state.yield_stress = yield_end.stress;
  out.state.temperature = theta + p_.heat_fraction * yield_end.stress * d_eps / (p_.density * p_.specific_heat);
  return out;
}

void J2JohnsonCook::stress_and_tangent(const Eigen::Matrix2d& f, const MaterialState& start, double dgamma,
                                       double yield_stress, double slope, StressResponse& out) const {
  // The update's stress formulas in dual numbers with F's four entries as variables; Δγ enters as
  // Δγ − r/r′ so that its derivative is −(∂r/∂F)/r′ (implicit-function theorem).
  using D = Dual<4>;
  Eigen::Matrix<D, 2, 2> fd;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) fd(i, j) = D::variable(f(i, j), 2 * i + j);
  }
  const KirchhoffTrial<D> t = trial_strain<D>(fd, start);
  const D q = 2.0 * mu_ * t.norm;
  D scale = D(1.0);
  if (dgamma > 0.0) {
    const D r = q - 2.0 * mu_ * dgamma - kSqrtTwoThirds * yield_stress;
    const D dg = dgamma - r / slope;
    scale = 1.0 - 2.0 * mu_ * dg / q;
  }
  const D pressure = kappa_ * t.volumetric;
  Eigen::Matrix<D, 2, 2> tau;
  tau(0, 0) = 2.0 * mu_ * t.dev.xx * scale + pressure;
  tau(1, 1) = 2.0 * mu_ * t.dev.yy * scale + pressure;
  tau(0, 1) = tau(1, 0) = 2.0 * mu_ * t.dev.xy * scale;
  // P = τ F⁻ᵀ.
  const D det = fd(0, 0) * fd(1, 1) - fd(0, 1) * fd(1, 0);
  Eigen::Matrix<D, 2, 2> inv_t;
  inv_t(0, 0) = fd(1, 1) / det;
  inv_t(0, 1) = -1.0 * fd(1, 0) / det;
  inv_t(1, 0) = -1.0 * fd(0, 1) / det;
  inv_t(1, 1) = fd(0, 0) / det;
  const Eigen::Matrix<D, 2, 2> p = tau * inv_t;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      out.stress(i, j) = p(i, j).v;
      out.tangent.row(2 * i + j) = p(i, j).d.transpose();
    }
  }
}

double Material::shear_yield_stress(const MaterialState&) const { return std::numeric_limits<double>::infinity(); }

double J2JohnsonCook::shear_yield_stress(const MaterialState& at) const {
  return johnson_cook_yield_stress(p_, at.equivalent_plastic_strain, at.plastic_strain_rate, at.temperature) / std::sqrt(3.0);
}

}  // namespace mufric::solid
