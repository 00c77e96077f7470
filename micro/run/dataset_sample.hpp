#pragma once
// One dataset sample = one micro-model run of a scene at a plan point: the plan's inputs set the
// scene's load (contact_pressure → load.pressure, sliding_velocity → load.velocity, temperature →
// load.temperature); μ and the run's diagnostics become the sample.
#include "common/input_space.hpp"
#include "common/sample_outcome.hpp"
#include "micro/scene/scene.hpp"

namespace mufric::run {

// Throws Error when an input has no counterpart in the scene (e.g. fibre_angle), a required one is
// missing, or the scene is loaded by a displacement instead of a pressure. Each run uses
// `threads_per_sample` OpenMP threads (several samples may run at once). A sample still running after
// `sample_wall_seconds` (> 0) stops and is recorded as failed, with where it stopped. A request's seeds
// replace the scene's tool and chip seeds (draw r then uses seed + r, as protocol_draws says).
SampleEvaluator micro_evaluator(const scene::Scene& scene, const InputSpace& inputs, int threads_per_sample,
                                double sample_wall_seconds = 0.0);

}  // namespace mufric::run
