#pragma once
// What one dataset sample's evaluation gives back, and the evaluator that gives it. A plain struct
// in common/ because two layers meet at it without depending on each other's code: micro/scene
// produces it (micro_evaluator, one micro-model run per plan point) and campaign/ consumes it
// (generate_dataset, merge, refine), which also runs evaluators that are not the micro-model (the
// tests' fake ones). In micro/scene it would tie campaign/'s generation to the micro-solver's headers;
// in campaign/ micro/ would depend on the layer above it.
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace mufric {

struct SampleOutcome {
  bool converged = false;
  double mu = std::numeric_limits<double>::quiet_NaN();
  double mu_std = std::numeric_limits<double>::quiet_NaN();  // μ's standard error (NaN: not known)
  std::string failure_reason;                 // why not converged
  // A converged sample outside what the model describes (a molten chip): stored with status
  // outside_model and these sentences as its reason, and never trained on.
  std::vector<std::string> warnings;
  std::map<std::string, double> diagnostics;  // SI, named as in /samples/diagnostics
};
// Evaluates one point (SI, in the plan's input order). May throw: the sample is then recorded as
// failed with the exception's message.
using SampleEvaluator = std::function<SampleOutcome(const Eigen::VectorXd& x)>;

}  // namespace mufric
