// The coupling's glue without the meso code (issue 69): a stand-in caller with the signature of the
// SPH contact's friction law (contact_friction_law::coefficients in the patched contact.h) hands the
// glue a block of particles as the contact algorithm would, and each answer is checked against
// mufric's C ABI called directly. Part of the mfree_iwf-ul-cut-refine coupling; GPL-3.0-or-later.
//   test_mufric_contact_glue MODEL.h5 (a calibrated mu(p, v, T) model, e.g. the shipped ti6al4v_tin)
#include <cfenv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <mufric/mufric.h>

#include "mufric_contact_glue.h"

namespace {
std::string g_model;

// The SPH contact's friction-law call: n particles, normal force per metre of depth, contact
// length, slip speed, temperature; mu out.
struct stand_in_sph_contact {
  mufric_contact_glue* glue;
  int last_rc = 0;
  void coefficients(unsigned n, const double* force, const double* length, const double* slip, const double* T,
                    double* mu) {
    last_rc = mufric_glue_friction(glue, n, force, length, slip, T, mu);
  }
};

constexpr double kSpacing = 10e-6;   // m: a particle's contact length at 10 um spacing
constexpr double kFallbackMu = 0.35;

struct direct_answer {
  std::vector<double> mu, lo, hi;
  std::vector<int> status;
};

// mufric's C ABI on the model directly, at contact pressures the test computes itself.
direct_answer evaluate_directly(const std::vector<double>& p, const std::vector<double>& v, const std::vector<double>& T) {
  mufric_client* c = nullptr;
  EXPECT_EQ(mufric_open_with_options(("file://" + g_model).c_str(), "fill=0", &c), MUFRIC_OK) << mufric_last_error();
  direct_answer a;
  const size_t n = p.size();
  a.mu.resize(n);
  a.lo.resize(n);
  a.hi.resize(n);
  a.status.resize(n);
  mufric_evaluate(c, n, p.data(), v.data(), T.data(), nullptr, 0.95, a.mu.data(), nullptr, a.lo.data(), a.hi.data(),
                  a.status.data());
  mufric_close(c);
  return a;
}

mufric_contact_glue* open_glue(int use) {
  mufric_contact_glue* g = nullptr;
  EXPECT_EQ(mufric_glue_open(("file://" + g_model).c_str(), "", kFallbackMu, use, 0.95, &g), 0) << mufric_glue_error();
  return g;
}

// A rake-face block as the SPH cut makes it: penalty forces of 5-15 kN/m on particles of 10 um, chip
// speeds of 0.2-0.6 m/s, 500-900 C.
struct contact_block {
  std::vector<double> force, length, slip, T;
  explicit contact_block(unsigned n) {
    for (unsigned i = 0; i < n; ++i) {
      const double s = (i + 0.5) / n;
      force.push_back(5e3 + 1e4 * s);
      length.push_back(kSpacing);
      slip.push_back(0.2 + 0.4 * s);
      T.push_back(773.15 + 400.0 * (1.0 - s));
    }
  }
  std::vector<double> pressure() const {
    std::vector<double> p;
    for (size_t i = 0; i < force.size(); ++i) p.push_back(force[i] / length[i]);
    return p;
  }
};
}  // namespace

TEST(MesoSphGlue, PressureIsTheNormalForceOverTheContactLengthInSi) {
  mufric_contact_glue* g = open_glue(MUFRIC_GLUE_MEAN);
  stand_in_sph_contact contact{g};
  const contact_block block(16);
  std::vector<double> mu(16, -1.0);
  contact.coefficients(16, block.force.data(), block.length.data(), block.slip.data(), block.T.data(), mu.data());
  EXPECT_EQ(contact.last_rc, 0) << mufric_glue_error();
  const direct_answer direct = evaluate_directly(block.pressure(), block.slip, block.T);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(direct.status[i], MUFRIC_POINT_OK) << "point " << i << " should lie inside the model's box";
    EXPECT_NEAR(mu[i], direct.mu[i], 1e-12) << "point " << i;
  }
  // a force twice as large on the same length is another pressure: the glue must not pass the force on
  std::vector<double> doubled = block.force, mu2(16);
  for (double& f : doubled) f *= 2.0;
  contact.coefficients(16, doubled.data(), block.length.data(), block.slip.data(), block.T.data(), mu2.data());
  int differing = 0;
  for (int i = 0; i < 16; ++i) differing += std::fabs(mu2[i] - mu[i]) > 1e-6;
  EXPECT_GT(differing, 0) << "mu does not move with the pressure: is the model mu(p, v, T)?";
  mufric_glue_close(g);
}

TEST(MesoSphGlue, OneCallForTheBlockAnswersAsOneCallPerParticle) {
  mufric_contact_glue* g = open_glue(MUFRIC_GLUE_MEAN);
  const contact_block block(40);
  std::vector<double> batched(40), single(40);
  ASSERT_EQ(mufric_glue_friction(g, 40, block.force.data(), block.length.data(), block.slip.data(), block.T.data(),
                                 batched.data()), 0);
  for (int i = 0; i < 40; ++i) {
    ASSERT_EQ(mufric_glue_friction(g, 1, &block.force[i], &block.length[i], &block.slip[i], &block.T[i], &single[i]), 0);
    EXPECT_NEAR(single[i], batched[i], 1e-12) << "point " << i;
  }
  EXPECT_EQ(mufric_glue_counts_so_far(g)->calls, 41u);
  EXPECT_EQ(mufric_glue_counts_so_far(g)->points, 80u);
  mufric_glue_close(g);
}

TEST(MesoSphGlue, AStepWithoutContactIsANoOp) {
  mufric_contact_glue* g = open_glue(MUFRIC_GLUE_MEAN);
  double mu = -7.0;
  EXPECT_EQ(mufric_glue_friction(g, 0, nullptr, nullptr, nullptr, nullptr, &mu), 0);
  EXPECT_EQ(mu, -7.0);
  EXPECT_EQ(mufric_glue_counts_so_far(g)->calls, 0u);
  mufric_glue_close(g);
}

TEST(MesoSphGlue, PointsWithoutAnAnswerGetTheCodesConstantAndNoFloatingPointTrapFires) {
  mufric_contact_glue* g = open_glue(MUFRIC_GLUE_MEAN);
  contact_block block(4);
  block.T[1] = std::nan("");   // a broken temperature
  block.length[2] = 0.0;       // no contact length: no pressure
  std::vector<double> mu(4, -1.0);
  // the patched SPH code runs with these traps on (upstream's main enables them)
  feclearexcept(FE_ALL_EXCEPT);
  feenableexcept(FE_INVALID | FE_OVERFLOW | FE_DIVBYZERO);
  const int rc = mufric_glue_friction(g, 4, block.force.data(), block.length.data(), block.slip.data(), block.T.data(), mu.data());
  fedisableexcept(FE_INVALID | FE_OVERFLOW | FE_DIVBYZERO);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(std::string(mufric_glue_error()).find("fallback"), std::string::npos) << mufric_glue_error();
  EXPECT_EQ(mu[1], kFallbackMu);
  EXPECT_EQ(mu[2], kFallbackMu);
  EXPECT_NE(mu[0], kFallbackMu);
  EXPECT_NE(mu[3], kFallbackMu);
  EXPECT_EQ(mufric_glue_counts_so_far(g)->unanswered, 2u);
  mufric_glue_close(g);
}

TEST(MesoSphGlue, ABlockOutsideTheBoxIsAnsweredByTheModelsPolicyAndCountedPerInput) {
  mufric_contact_glue* g = open_glue(MUFRIC_GLUE_MEAN);
  double lo[3], hi[3];
  mufric_glue_box(g, lo, hi);
  // a cold particle at first contact (20 C) and one at the stagnation point (no slip)
  const std::vector<double> force = {1e4, 1e4}, length = {kSpacing, kSpacing}, slip = {0.3, 0.0}, T = {293.15, 900.0};
  std::vector<double> mu(2);
  ASSERT_EQ(mufric_glue_friction(g, 2, force.data(), length.data(), slip.data(), T.data(), mu.data()), 0) << mufric_glue_error();
  // the clamp policy of the shipped model: mu of the nearest point of the box
  const direct_answer at_faces = evaluate_directly({1e9, 1e9}, {0.3, lo[1]}, {lo[2], 900.0});
  EXPECT_NEAR(mu[0], at_faces.mu[0], 1e-12);
  EXPECT_NEAR(mu[1], at_faces.mu[1], 1e-12);
  const mufric_glue_counts* c = mufric_glue_counts_so_far(g);
  EXPECT_EQ(c->extrapolated, 2u);
  EXPECT_EQ(c->outside[2][0], 1u);  // temperature below
  EXPECT_EQ(c->outside[1][0], 1u);  // sliding velocity below
  EXPECT_EQ(c->outside[0][0] + c->outside[0][1], 0u);
  mufric_glue_close(g);
}

TEST(MesoSphGlue, TheIntervalsEndsAreTheModelsLoAndHi) {
  const contact_block block(8);
  const direct_answer direct = evaluate_directly(block.pressure(), block.slip, block.T);
  for (const int use : {MUFRIC_GLUE_LOWER, MUFRIC_GLUE_UPPER}) {
    mufric_contact_glue* g = open_glue(use);
    std::vector<double> mu(8);
    ASSERT_EQ(mufric_glue_friction(g, 8, block.force.data(), block.length.data(), block.slip.data(), block.T.data(), mu.data()), 0);
    for (int i = 0; i < 8; ++i) {
      const double expected = use == MUFRIC_GLUE_LOWER ? direct.lo[i] : direct.hi[i];
      EXPECT_NEAR(mu[i], std::fmax(0.0, expected), 1e-12) << "point " << i;
      EXPECT_NE(mu[i], direct.mu[i]);
    }
    mufric_glue_close(g);
  }
}

TEST(MesoSphGlue, ContactStatesAreLoggedEveryNthCallWithUnits) {
  mufric_contact_glue* g = open_glue(MUFRIC_GLUE_MEAN);
  const std::string path = ::testing::TempDir() + "glue_states.csv";
  std::remove(path.c_str());
  ASSERT_EQ(mufric_glue_log_states(g, path.c_str(), 2), 0);
  const contact_block block(3);
  std::vector<double> mu(3);
  for (int call = 0; call < 5; ++call) {
    mufric_glue_friction(g, 3, block.force.data(), block.length.data(), block.slip.data(), block.T.data(), mu.data());
  }
  mufric_glue_close(g);
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header, "call,contact_pressure[Pa],sliding_velocity[m/s],temperature[K],mu[1],lo[1],hi[1],status");
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 9);  // calls 0, 2 and 4, three points each
}

TEST(MesoSphGlue, BadSettingsAreRefusedNamingThem) {
  mufric_contact_glue* g = nullptr;
  EXPECT_EQ(mufric_glue_open(("file://" + g_model).c_str(), "", -1.0, MUFRIC_GLUE_MEAN, 0.95, &g), 1);
  EXPECT_NE(std::string(mufric_glue_error()).find("fallback_mu"), std::string::npos);
  EXPECT_EQ(mufric_glue_open(("file://" + g_model).c_str(), "", 0.35, 7, 0.95, &g), 1);
  EXPECT_NE(std::string(mufric_glue_error()).find("use"), std::string::npos);
  EXPECT_EQ(mufric_glue_open("file:///no/such/model.h5", "", 0.35, MUFRIC_GLUE_MEAN, 0.95, &g), 1);
  EXPECT_NE(std::string(mufric_glue_error()).find("model.h5"), std::string::npos) << mufric_glue_error();
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s MODEL.h5\n", argv[0]);
    return 2;
  }
  g_model = argv[1];
  return RUN_ALL_TESTS();
}
