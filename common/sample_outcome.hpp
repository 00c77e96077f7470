#pragma once
// What one dataset sample's evaluation gives back, and the evaluator that gives it. A plain struct
// in common/ because two layers meet at it without depending on each other's code: micro/scene
// produces it (micro_evaluator, one micro-model run per plan point) and campaign/ consumes it
// (generate_dataset, merge, refine), which also runs evaluators that are not the micro-model (the
// tests' fake ones). In micro/scene it would tie campaign/'s generation to the micro-solver's headers;
// in campaign/ micro/ would depend on the layer above it.
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace mufric {

// The roughness a sample is drawn with: the base seeds of its tool and chip surfaces (draw r of the
// sample uses base + r). A plan with independent draws gives every row its own (campaign/
// row_draw_seeds); a plan with common draws none, and every sample uses the scene's own seeds.
struct DrawSeeds {
  std::uint64_t tool = 0, chip = 0;
};

// What an evaluator is asked: the point (SI, in the plan's input order), the plan row it answers, and
// the row's seeds when its draws are its own.
struct SampleRequest {
  Eigen::VectorXd x;
  long long plan_row = -1;
  std::optional<DrawSeeds> seeds;
};

struct SampleOutcome {
  bool converged = false;
  double mu = std::numeric_limits<double>::quiet_NaN();
  double mu_std = std::numeric_limits<double>::quiet_NaN();  // μ's standard error (NaN: not known)
  std::string failure_reason;                 // why not converged
  // A converged sample outside what the model describes (a molten chip): stored with status
  // outside_model and these sentences as its reason, and never trained on.
  std::vector<std::string> warnings;
  std::map<std::string, double> diagnostics;  // SI, named as in /samples/diagnostics
  std::vector<double> draw_mu;                // each draw's μ, in draw order (empty: not known)
  // Failed with its μ and standard error kept readable (a sample the learner quarantined: its values
  // were refused, not missing); a merge keeps what its files hold. Otherwise a failed sample's are NaN.
  bool keep_values_when_failed = false;
};
// Evaluates one request. May throw: the sample is then recorded as failed with the exception's message.
using SampleEvaluator = std::function<SampleOutcome(const SampleRequest& request)>;

}  // namespace mufric
