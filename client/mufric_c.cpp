// The C ABI over the C++ client: every exception stops here and becomes a status code.
#include <array>
#include <cmath>
#include <exception>
#include <memory>
#include <string>
#include <string_view>

#include "client/friction_client.hpp"
#include "client/mufric.h"

struct mufric_client {
  std::unique_ptr<mufric::client::FrictionClient> impl;
  double mu_tolerance = 0.0, std_tolerance = 0.0;  // from the options (a fast evaluator's admission)
  mufric::Extrapolation extrapolation = mufric::Extrapolation::model_default;
  // The model's training box in mufric_evaluate's argument order, read once at open (mufric_box,
  // the outside flags); an input the model does not take is not used, with a box of [0, 0].
  static constexpr std::array<std::string_view, 4> input_names{"contact_pressure", "sliding_velocity", "temperature",
                                                               "fibre_angle"};
  std::array<bool, 4> used{};
  std::array<mufric::InputSpec, 4> box{};
  bool has_patch_scatter = false;  // read at open too
};

namespace {

thread_local std::string last_error;

int fail(int code, std::string message) {
  last_error = std::move(message);
  return code;
}

// A call's body with the C API's error contract: an invalid argument or any other failure becomes its
// code, and mufric_last_error says what, prefixed by the function's name.
template <class Body>
int guarded(const char* function, Body&& body) {
  try {
    return body();
  } catch (const mufric::client::InvalidArgument& e) {
    return fail(MUFRIC_INVALID_ARGUMENT, std::string(function) + ": " + e.what());
  } catch (const std::exception& e) {
    return fail(MUFRIC_FAILED, std::string(function) + ": " + e.what());
  }
}

// A request with the client's tolerances and extrapolation policy (mufric_open's options).
mufric::client::Answer evaluate_with_options(const mufric_client& client, const mufric::client::Block& block, mufric::EvaluationRequest what) {
  what.mu_tolerance = client.mu_tolerance;
  what.std_relative_tolerance = client.std_tolerance;
  what.extrapolation = client.extrapolation;
  return client.impl->evaluate(block, what);
}

// A Fortran CHARACTER argument: its hidden length, blank padding removed.
std::string fortran_string(const char* text, size_t length) {
  std::string s(text, length);
  s.erase(s.find_last_not_of(' ') + 1);
  return s;
}

}  // namespace

extern "C" {

int mufric_open(const char* uri, mufric_client** client) { return mufric_open_with_options(uri, nullptr, client); }

int mufric_open_with_options(const char* uri, const char* options, mufric_client** client) {
  if (uri == nullptr || client == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, "mufric_open: uri and client must not be NULL");
  *client = nullptr;
  mufric::client::Options parsed;
  try {
    parsed = mufric::client::parse_options(options ? options : "");
  } catch (const std::exception& e) {
    return fail(MUFRIC_INVALID_ARGUMENT, std::string("mufric_open: ") + e.what());
  }
  try {
    auto handle = std::make_unique<mufric_client>();
    handle->impl = mufric::client::connect(uri, parsed);
    handle->mu_tolerance = parsed.mu_tolerance;
    handle->std_tolerance = parsed.std_tolerance;
    handle->extrapolation = parsed.extrapolation;
    // Fails now, not at the first evaluation, if the model is not there.
    const mufric::client::ModelInfo info = handle->impl->describe();
    handle->has_patch_scatter = info.has_patch_scatter;
    for (const auto& input : info.inputs) {
      for (size_t k = 0; k < mufric_client::input_names.size(); ++k) {
        if (input.name != mufric_client::input_names[k]) continue;
        handle->used[k] = true;
        handle->box[k] = input;
      }
    }
    *client = handle.release();
    last_error.clear();
    return MUFRIC_OK;
  } catch (const std::exception& e) {
    return fail(MUFRIC_FAILED, std::string("mufric_open: ") + e.what());
  }
}

void mufric_close(mufric_client* client) { delete client; }

int mufric_evaluate(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                    const double* temperature, const double* fibre_angle, double ci_level, double* mu, double* std,
                    double* lo, double* hi, int* status) {
  return mufric_evaluate_ex(client, n, contact_pressure, sliding_velocity, temperature, fibre_angle, ci_level, mu, std,
                            lo, hi, status, nullptr, nullptr);
}

int mufric_evaluate_ex(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                       const double* temperature, const double* fibre_angle, double ci_level, double* mu, double* std,
                       double* lo, double* hi, int* status, unsigned* outside, mufric_counts* counts) {
  if (client == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, "mufric_evaluate: client is NULL");
  if (mu == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, "mufric_evaluate: mu must not be NULL");
  const bool want_interval = lo != nullptr || hi != nullptr;
  if (want_interval && !(ci_level > 0.0 && ci_level < 1.0)) {
    return fail(MUFRIC_INVALID_ARGUMENT, "mufric_evaluate: lo/hi requested but ci_level is not in (0, 1)");
  }
  return guarded("mufric_evaluate", [&] {
    const mufric::client::Block block{n, contact_pressure, sliding_velocity, temperature, fibre_angle};
    const auto answer = evaluate_with_options(*client, block, {.std = std != nullptr, .ci_level = want_interval ? ci_level : 0.0, .gradient = false});
    // Copies only: the outputs of points without an answer are NaN or the fill value, and nothing
    // here compares them (a caller trapping FE_INVALID would die on an ordered comparison with NaN).
    for (size_t i = 0; i < n; ++i) {
      mu[i] = answer.mu[i];
      if (std) std[i] = answer.std[i];
      if (lo) lo[i] = answer.lo[i];
      if (hi) hi[i] = answer.hi[i];
      if (status) status[i] = static_cast<int>(answer.status[i]);
    }
    if (outside) {
      const std::array<const double*, 4> inputs{contact_pressure, sliding_velocity, temperature, fibre_angle};
      for (size_t i = 0; i < n; ++i) {
        unsigned bits = 0;
        for (unsigned k = 0; k < 4; ++k) {
          if (!client->used[k] || inputs[k] == nullptr) continue;
          const double x = inputs[k][i];
          const mufric::InputSpec& input = client->box[k];
          // Outside as the model sees it (an angle a half turn away from the box is inside). A NaN
          // sets no bit and is never compared: isnan, isless and isgreater are quiet, where an
          // ordered comparison would raise FE_INVALID in a caller that traps it.
          if (std::isnan(x) || input.contains(x)) continue;
          if (std::isless(x, input.lo)) bits |= 1u << (2 * k);
          if (std::isgreater(x, input.hi)) bits |= 1u << (2 * k + 1);
        }
        outside[i] = bits;
      }
    }
    if (counts) {
      *counts = mufric_counts{};
      for (const auto s : answer.status) {
        counts->extrapolated += s == mufric::PointStatus::extrapolated;
        counts->invalid += s == mufric::PointStatus::invalid_input;
        counts->out_of_box += s == mufric::PointStatus::out_of_box;
      }
      counts->range_clipped = static_cast<size_t>(answer.range_clipped);
      counts->fast_points = static_cast<size_t>(answer.fast_points);
    }
    // A call with points without an answer succeeds; their message is what mufric_last_error says.
    last_error = answer.message;
    return MUFRIC_OK;
  });
}

int mufric_patch_std(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                     const double* temperature, const double* fibre_angle, double* patch_std, int* status) {
  if (client == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, "mufric_patch_std: client is NULL");
  if (patch_std == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, "mufric_patch_std: patch_std must not be NULL");
  if (!client->has_patch_scatter) {
    return fail(MUFRIC_INVALID_ARGUMENT, "mufric_patch_std: the model has no patch scatter (it was not trained by "
                                         "stochastic kriging on a dataset of independent draws)");
  }
  return guarded("mufric_patch_std", [&] {
    const mufric::client::Block block{n, contact_pressure, sliding_velocity, temperature, fibre_angle};
    const auto answer = evaluate_with_options(*client, block, {.patch_std = true});
    for (size_t i = 0; i < n; ++i) {  // copies only, as in mufric_evaluate_ex
      patch_std[i] = answer.patch_std[i];
      if (status) status[i] = static_cast<int>(answer.status[i]);
    }
    last_error = answer.message;
    return MUFRIC_OK;
  });
}

int mufric_has_patch_scatter(mufric_client* client) { return client != nullptr && client->has_patch_scatter ? 1 : 0; }

int mufric_box(mufric_client* client, int used[4], double lo[4], double hi[4]) {
  if (client == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, "mufric_box: client is NULL");
  for (size_t k = 0; k < 4; ++k) {
    if (used) used[k] = client->used[k] ? 1 : 0;
    if (lo) lo[k] = client->box[k].lo;
    if (hi) hi[k] = client->box[k].hi;
  }
  last_error.clear();
  return MUFRIC_OK;
}

const char* mufric_last_error(void) { return last_error.c_str(); }

void mufric_open_(const char* uri, int64_t* handle, int32_t* status, size_t uri_length) {
  const std::string text = fortran_string(uri, uri_length);
  mufric_client* client = nullptr;
  *status = mufric_open(text.c_str(), &client);
  *handle = reinterpret_cast<int64_t>(client);
}

void mufric_open_with_options_(const char* uri, const char* options, int64_t* handle, int32_t* status,
                               size_t uri_length, size_t options_length) {
  const std::string text = fortran_string(uri, uri_length);
  const std::string option_text = fortran_string(options, options_length);
  mufric_client* client = nullptr;
  *status = mufric_open_with_options(text.c_str(), option_text.c_str(), &client);
  *handle = reinterpret_cast<int64_t>(client);
}

void mufric_evaluate_(const int64_t* handle, const int32_t* n, const double* contact_pressure,
                      const double* sliding_velocity, const double* temperature, const double* fibre_angle, double* mu,
                      int32_t* status) {
  *status = mufric_evaluate(reinterpret_cast<mufric_client*>(*handle), static_cast<size_t>(*n), contact_pressure,
                            sliding_velocity, temperature, fibre_angle, 0.0, mu, nullptr, nullptr, nullptr, nullptr);
}

void mufric_close_(const int64_t* handle) { mufric_close(reinterpret_cast<mufric_client*>(*handle)); }

}  // extern "C"
