#pragma once
// Helpers shared by the micro-model's end-to-end tests (test_micro_run.cpp and the long
// verification studies, test_verification_studies.cpp).
#include <gtest/gtest.h>

#include <string>

#include "micro/run/measurement.hpp"

namespace mufric::scene::test {

// μ of a scene given as JSON, with the test failed (not stopped) when the measurement did not complete.
inline run::MuMeasurement measure(const nlohmann::json& j, const std::string& name) {
  run::MuMeasurement m = run::measure_mu(parse_scene(j, name));
  EXPECT_TRUE(m.completed) << name << ": " << m.reason;
  return m;
}

}  // namespace mufric::scene::test
