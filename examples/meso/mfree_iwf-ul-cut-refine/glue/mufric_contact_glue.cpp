// The coupling's glue: a particle contact block in, mu per particle out, through mufric's C ABI.
// Part of the mfree_iwf-ul-cut-refine coupling; GPL-3.0-or-later like that code.
#include "mufric_contact_glue.h"

#include <mufric/mufric.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {
thread_local std::string last_error;

constexpr int kInputs = 3;  // contact pressure, sliding velocity, temperature
}  // namespace

struct mufric_contact_glue {
  mufric_client* client = nullptr;
  int use = MUFRIC_GLUE_MEAN;
  double ci_level = 0.95;
  double lo[kInputs] = {0, 0, 0}, hi[kInputs] = {0, 0, 0};
  mufric_glue_counts counts{};
  std::vector<double> pressure, mu, lo_out, hi_out;
  std::vector<int> status;
  std::vector<unsigned> outside;
  FILE* states = nullptr;
  size_t states_every = 0;
};

extern "C" {

const char* mufric_glue_error(void) { return last_error.c_str(); }

int mufric_glue_open(const char* uri, const char* options, double fallback_mu, int use, double ci_level,
                     mufric_contact_glue** glue) {
  if (glue == nullptr || uri == nullptr) {
    last_error = "mufric_glue_open: null uri or handle";
    return 1;
  }
  if (!(fallback_mu >= 0.0 && fallback_mu <= 10.0)) {
    last_error = "mufric_glue_open: fallback_mu must lie in [0, 10]";
    return 1;
  }
  if (use != MUFRIC_GLUE_MEAN && use != MUFRIC_GLUE_LOWER && use != MUFRIC_GLUE_UPPER) {
    last_error = "mufric_glue_open: use must be MEAN, LOWER or UPPER";
    return 1;
  }
  if (!(ci_level > 0.0 && ci_level < 1.0)) {
    last_error = "mufric_glue_open: ci_level must lie in (0, 1)";
    return 1;
  }
  // fallback_mu for points without an answer; fill=0 so that no NaN reaches a code that traps
  // FE_INVALID in std, lo or hi of such points either.
  std::string all = "fill=0, fallback_mu=" + std::to_string(fallback_mu);
  if (options != nullptr && *options != '\0') all += std::string(", ") + options;
  auto* g = new mufric_contact_glue;
  if (mufric_open_with_options(uri, all.c_str(), &g->client) != MUFRIC_OK) {
    last_error = std::string("mufric_glue_open: ") + mufric_last_error();
    delete g;
    return 1;
  }
  int used[4];
  double lo[4], hi[4];
  mufric_box(g->client, used, lo, hi);
  for (int k = 0; k < kInputs; ++k) {
    if (!used[k]) {
      last_error = std::string("mufric_glue_open: model '") + uri + "' does not take input " + std::to_string(k) +
                   " (contact pressure, sliding velocity, temperature): it is no mu(p, v, T)";
      mufric_close(g->client);
      delete g;
      return 1;
    }
    g->lo[k] = lo[k];
    g->hi[k] = hi[k];
  }
  g->use = use;
  g->ci_level = ci_level;
  *glue = g;
  last_error.clear();
  return 0;
}

void mufric_glue_box(const mufric_contact_glue* glue, double lo[3], double hi[3]) {
  for (int k = 0; k < kInputs; ++k) {
    lo[k] = glue->lo[k];
    hi[k] = glue->hi[k];
  }
}

int mufric_glue_log_states(mufric_contact_glue* glue, const char* path, size_t every) {
  if (glue->states != nullptr) fclose(glue->states);
  glue->states = nullptr;
  glue->states_every = every;
  if (every == 0) return 0;
  FILE* f = std::fopen(path, "a");
  if (f == nullptr) {
    last_error = std::string("mufric_glue_log_states: cannot open '") + path + "'";
    return 1;
  }
  std::fseek(f, 0, SEEK_END);
  if (std::ftell(f) == 0) {
    std::fputs("call,contact_pressure[Pa],sliding_velocity[m/s],temperature[K],mu[1],lo[1],hi[1],status\n", f);
  }
  glue->states = f;
  return 0;
}

int mufric_glue_friction_at(mufric_contact_glue* g, size_t n, const double* p, const double* v, const double* T,
                            double* mu_out) {
  if (n == 0) return 0;
  const auto start = std::chrono::steady_clock::now();
  g->mu.resize(n);
  g->lo_out.resize(n);
  g->hi_out.resize(n);
  g->status.resize(n);
  g->outside.resize(n);
  mufric_counts counts{};
  mufric_outputs out{};
  out.mu = g->mu.data();
  // The interval only where it is used: a clamped point's interval needs the model at the real point
  // outside the box, where no fast grid answers (the exact calibrated predictive: milliseconds).
  const bool log_this_call = g->states != nullptr && g->counts.calls % g->states_every == 0;
  const bool want_interval = g->use != MUFRIC_GLUE_MEAN || log_this_call;
  if (want_interval) {
    out.lo = g->lo_out.data();
    out.hi = g->hi_out.data();
  } else {
    std::fill(g->lo_out.begin(), g->lo_out.end(), 0.0);
    std::fill(g->hi_out.begin(), g->hi_out.end(), 0.0);
  }
  out.status = g->status.data();
  out.outside = g->outside.data();
  out.counts = &counts;
  const int rc = mufric_evaluate_outputs(g->client, n, p, v, T, nullptr, want_interval ? g->ci_level : 0.0, &out);
  if (rc != MUFRIC_OK && rc != MUFRIC_PARTIAL) {
    last_error = std::string("mufric_glue_friction: ") + mufric_last_error();
    return 1;
  }
  const std::string message = rc == MUFRIC_PARTIAL ? mufric_last_error() : "";
  for (size_t i = 0; i < n; ++i) {
    const bool answered = g->status[i] == MUFRIC_POINT_OK || g->status[i] == MUFRIC_POINT_EXTRAPOLATED;
    double value = g->mu[i];  // fallback_mu where not answered
    if (answered && g->use == MUFRIC_GLUE_LOWER) value = g->lo_out[i];
    if (answered && g->use == MUFRIC_GLUE_UPPER) value = g->hi_out[i];
    mu_out[i] = std::fmax(0.0, value);
    for (int k = 0; k < kInputs; ++k) {
      if (g->outside[i] & (1u << (2 * k))) ++g->counts.outside[k][0];
      if (g->outside[i] & (1u << (2 * k + 1))) ++g->counts.outside[k][1];
    }
  }
  if (log_this_call) {
    for (size_t i = 0; i < n; ++i) {
      std::fprintf(g->states, "%zu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d\n", g->counts.calls, p[i], v[i], T[i], mu_out[i],
                   g->lo_out[i], g->hi_out[i], g->status[i]);
    }
    std::fflush(g->states);
  }
  ++g->counts.calls;
  g->counts.points += n;
  g->counts.extrapolated += counts.extrapolated;
  g->counts.unanswered += counts.invalid + counts.out_of_box;
  g->counts.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (rc == MUFRIC_PARTIAL) {
    last_error = "mufric_glue_friction: fallback mu at some points: " + message;
    return 2;
  }
  return 0;
}

int mufric_glue_friction(mufric_contact_glue* g, size_t n, const double* normal_force, const double* contact_length,
                         const double* slip_speed, const double* temperature, double* mu) {
  if (n == 0) return 0;
  const auto start = std::chrono::steady_clock::now();
  g->pressure.resize(n);
  // A zero or negative contact length is no contact: its pressure is not a number, which mufric
  // answers INVALID_INPUT and the glue gives fallback_mu.
  for (size_t i = 0; i < n; ++i) {
    g->pressure[i] = contact_length[i] > 0.0 ? std::fabs(normal_force[i]) / contact_length[i] : -1.0;
  }
  g->counts.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return mufric_glue_friction_at(g, n, g->pressure.data(), slip_speed, temperature, mu);
}

const mufric_glue_counts* mufric_glue_counts_so_far(const mufric_contact_glue* glue) { return &glue->counts; }

void mufric_glue_close(mufric_contact_glue* glue) {
  if (glue == nullptr) return;
  if (glue->states != nullptr) std::fclose(glue->states);
  mufric_close(glue->client);
  delete glue;
}

}  // extern "C"
