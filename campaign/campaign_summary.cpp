#include "campaign/campaign_summary.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/wording.hpp"

namespace mufric {
namespace {

// "mesh 64 x 12 of degree 2" from a micro-model scene's text; empty when the scene does not say (a
// key left out takes the code's default, which this layer does not know) or there is no scene.
std::string mesh_text(const std::string& scene_json) {
  if (scene_json.empty()) return "";
  const nlohmann::json scene = nlohmann::json::parse(scene_json, nullptr, false);
  if (scene.is_discarded() || !scene.contains("discretisation")) return "";
  const nlohmann::json& d = scene["discretisation"];
  if (!d.is_object() || !d.contains("elements_x") || !d.contains("elements_y") || !d.contains("degree")) return "";
  if (!d["elements_x"].is_number_integer() || !d["elements_y"].is_number_integer() || !d["degree"].is_number_integer()) {
    return "";
  }
  return "mesh " + std::to_string(d["elements_x"].get<long long>()) + " x " + std::to_string(d["elements_y"].get<long long>()) +
         " of degree " + std::to_string(d["degree"].get<long long>());
}

}  // namespace

std::string campaign_summary(const Dataset& d) {
  long long converged = 0, outside = 0, draws = 0;
  std::vector<long long> per_sample;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (d.outside_model(i)) ++outside;
    if (!d.converged(i)) continue;
    ++converged;
    if (d.draw_mu.cols() > 0 && d.draw_mu.rows() == d.size()) {
      const auto finite = static_cast<long long>(d.draw_mu.row(i).array().isFinite().count());
      draws += finite;
      per_sample.push_back(finite);
    }
  }
  std::string s = d.source.empty() ? std::string("samples of unknown origin") : d.source;
  if (!d.code_version.empty()) s += ", created by code " + d.code_version;  // a resumed campaign keeps its first
  if (d.plan.rows() > 0) {
    s += "; plan " + count_of(d.plan.rows(), "point", "points");
    if (!d.plan_design.empty()) s += ", design " + d.plan_design + " (seed " + std::to_string(d.plan_seed) + ")";
  }
  s += "; draws ";
  s += d.draws == DrawDesign::independent ? "independent (every sample its own tool and chip surfaces)"
       : d.draws == DrawDesign::common    ? "common (every sample the scene's own surfaces)"
                                          : "common (a file from before draws were recorded)";
  if (!per_sample.empty()) {
    std::nth_element(per_sample.begin(), per_sample.begin() + static_cast<std::ptrdiff_t>(per_sample.size() / 2), per_sample.end());
    s += ", " + count_of(draws, "draw", "draws") + ", " + std::to_string(per_sample[per_sample.size() / 2]) + " per sample (median)";
  }
  if (const std::string mesh = mesh_text(d.scene_json); !mesh.empty()) s += "; " + mesh;
  s += "; " + count_of(d.size(), "sample", "samples") + " (" + std::to_string(converged) + " converged, " +
       std::to_string(outside) + " outside the model, " + std::to_string(d.size() - converged - outside) + " failed)";
  if (const std::optional<double> total = total_wall_seconds(d)) {
    s += "; micro-model wall time " + duration_text(*total) + " (" + duration_text(*total / static_cast<double>(d.size())) +
         " per sample)";
  }
  return s;
}

std::optional<double> total_wall_seconds(const Dataset& d) {
  const auto it = d.diagnostics.find("wall_seconds");
  if (it == d.diagnostics.end() || d.size() == 0) return std::nullopt;
  return it->second.array().isNaN().select(0.0, it->second.array()).sum();
}

}  // namespace mufric
