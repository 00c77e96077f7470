// Uses the installed package: the C++ client in-process on a model file given as argument.
#include <cmath>
#include <cstdio>
#include <numbers>

#include "client/friction_client.hpp"
#include <mufric/mufric.h>

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  const auto client = mufric::client::connect(argv[1]);
  const double p = 80e6, v = 10.0 / 60.0, angle = std::numbers::pi / 2;
  const auto answer = client->evaluate({1, &p, &v, nullptr, &angle}, {});
  // Seed 001 Table 4 at 90 deg: 0.149911 + 0.013133 * 10 - 0.000753 * 80 = 0.221001
  const bool ok = std::abs(answer.mu[0] - 0.221001) < 1e-12;
  mufric_client* c = nullptr;
  const bool c_ok = mufric_open(argv[1], &c) == MUFRIC_OK;
  mufric_close(c);
  std::printf("mu = %.6f via the installed package (%s)\n", answer.mu[0], ok && c_ok ? "as expected" : "WRONG");
  return ok && c_ok ? 0 : 1;
}
