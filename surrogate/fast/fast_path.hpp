#pragma once
// The one fast path of every model kind that carries a certified grid (FastEvaluator): which rows of
// a batch the grid answers, and how its answers and the exact model's are put together. A kind
// supplies its exact evaluation; the split, the grid and the fallback are here, so that a Gaussian
// process and a calibrated model (and a new kind) answer a request the same way.
#include <functional>

#include "surrogate/core/friction_model.hpp"
#include "surrogate/fast/fast_evaluator.hpp"

namespace mufric {

// A kind's exact answer for a batch: μ, σ when asked (what.std or a CI level) and the gradient when
// asked, for every row of x.
using ExactEvaluation = std::function<void(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out)>;

// Whether `fast` may answer `what` at all: there is a grid, the request is not exact-only, and the
// grid's certified bounds are within the request's tolerances.
bool grid_serves(const FastEvaluator* fast, const EvaluationRequest& what);

// μ and σ at the rows inside the grid's box from the grid, the others from `exact`; the gradient,
// when asked, is the exact model's at every row, and μ and σ inside the box stay the grid's, so that
// asking for the gradient does not move μ. out.fast_points counts the grid's rows.
void evaluate_through_grid(const FastEvaluator* fast, const QueryBatch& x, const EvaluationRequest& what,
                           const ExactEvaluation& exact, Evaluation& out);

}  // namespace mufric
