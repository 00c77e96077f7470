// `mufric micro …`: the micro-model's user-facing steps. So far: surface profiles (measured or
// synthetic), their roughness and their periodic spline fit.
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "app/commands.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "micro/spline/profile.hpp"

namespace mufric::app {
namespace {

struct ProfileOptions {
  std::string csv, period = "", length = "10um", ra = "0.2um", correlation = "1um", out;
  int samples = 512, degree = 3, control_points = 64;
  unsigned long long seed = 1;
};

double length_option(const std::string& text, const std::string& flag) {
  return parse_quantity(text, QuantityKind::length, flag);
}

void run_profile(const ProfileOptions& o) {
  spline::Profile profile;
  if (!o.csv.empty()) {
    profile = spline::read_profile_csv(o.csv, o.period.empty() ? 0.0 : length_option(o.period, "--period"));
  } else {
    spline::RoughnessSpec spec;
    spec.length = length_option(o.length, "--length");
    spec.ra = length_option(o.ra, "--ra");
    spec.correlation_length = length_option(o.correlation, "--correlation");
    spec.samples = o.samples;
    spec.seed = o.seed;
    profile = spline::synthetic_rough_profile(spec);
  }
  const auto r = spline::roughness_figures(profile);
  std::printf("profile %s: %zu samples over one period of %s\n", profile.source.c_str(), profile.x.size(),
              format_human(profile.period, QuantityKind::length).c_str());
  std::printf("  Ra %s  Rq %s  Rz %s  correlation length %s\n", format_human(r.ra, QuantityKind::length).c_str(),
              format_human(r.rq, QuantityKind::length).c_str(), format_human(r.rz, QuantityKind::length).c_str(),
              r.correlation_length > 0.0 ? format_human(r.correlation_length, QuantityKind::length).c_str()
                                         : "(longer than half the period)");
  const spline::ProfileFit fit = spline::fit_periodic_profile(profile, o.degree, o.control_points);
  std::printf("periodic spline fit, degree %d, %d control points: rms error %s, max error %s (%.2f %% of Rz)\n",
              o.degree, o.control_points, format_human(fit.rms_error, QuantityKind::length).c_str(),
              format_human(fit.max_error, QuantityKind::length).c_str(), r.rz > 0.0 ? 100.0 * fit.max_error / r.rz : 0.0);
  if (!o.out.empty()) {
    // Data and fitted curve side by side, for a plot: the curve at each datum's parameter.
    std::ofstream out(o.out);
    if (!out) throw Error("--out: cannot write '" + o.out + "'");
    out << "x[um],height[um],fit_x[um],fit_height[um]\n";
    out.precision(10);
    for (size_t k = 0; k < profile.x.size(); ++k) {
      const Eigen::Vector2d c = fit.curve.point(fit.parameters[k]);
      out << profile.x[k] * 1e6 << "," << profile.height[k] * 1e6 << "," << c.x() * 1e6 << "," << c.y() * 1e6 << "\n";
    }
    std::printf("wrote %s\n", o.out.c_str());
  }
}

}  // namespace

void add_micro_commands(CLI::App& app) {
  auto* micro = app.add_subcommand("micro", "The high-fidelity micro-model of the tool-chip contact zone");
  micro->require_subcommand(1);
  auto o = std::make_shared<ProfileOptions>();
  auto* profile = micro->add_subcommand(
      "profile", "Roughness of a surface profile (measured CSV or synthetic) and its periodic spline fit");
  profile->add_option("--csv", o->csv, "Measured profile: columns x and height with length units, e.g. x[um],height[nm]")
      ->check(CLI::ExistingFile);
  profile->add_option("--period", o->period, "Period of the measured profile (default: sampled range + one spacing)");
  profile->add_option("--length", o->length, "Synthetic: period")->capture_default_str();
  profile->add_option("--ra", o->ra, "Synthetic: arithmetic mean roughness Ra")->capture_default_str();
  profile->add_option("--correlation", o->correlation, "Synthetic: correlation length")->capture_default_str();
  profile->add_option("--samples", o->samples, "Synthetic: samples per period")->capture_default_str()
      ->check(CLI::Range(10, 1 << 20));
  profile->add_option("--seed", o->seed, "Synthetic: random seed")->capture_default_str();
  profile->add_option("--degree", o->degree, "Spline degree of the fit")->capture_default_str()->check(CLI::Range(1, 10));
  profile->add_option("--control-points", o->control_points, "Control points of the fit (one period)")
      ->capture_default_str()->check(CLI::Range(2, 100000));
  profile->add_option("--out", o->out, "CSV of the data and the fitted curve, for a plot");
  profile->footer("Without --csv a Gaussian random profile with a Gaussian autocorrelation is generated, scaled to\n"
                  "the requested Ra exactly. The fit is a periodic least-squares B-spline with chord-length\n"
                  "parameters; its error is the distance from each datum to the curve at the datum's parameter.");
  profile->callback([o] { run_profile(*o); });
}

}  // namespace mufric::app
