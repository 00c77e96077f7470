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
  static constexpr std::array<std::string_view, 4> input_names{
      mufric::input_name::contact_pressure, mufric::input_name::sliding_velocity, mufric::input_name::temperature,
      mufric::input_name::fibre_angle};
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

// Which output a function cannot do without (mufric_evaluate's mu, mufric_patch_std's patch_std).
enum class Required { nothing, mu, patch_std };

// The box flags of mufric_evaluate_ex: bit 2k below input k's box, 2k+1 above.
unsigned outside_bits(const mufric_client& client, const std::array<const double*, 4>& inputs, size_t i) {
  unsigned bits = 0;
  for (unsigned k = 0; k < 4; ++k) {
    if (!client.used[k] || inputs[k] == nullptr) continue;
    const double x = inputs[k][i];
    const mufric::InputSpec& input = client.box[k];
    // Outside as the model sees it (an angle a half turn away from the box is inside). A NaN sets no
    // bit and is never compared: isnan, isless and isgreater are quiet, where an ordered comparison
    // would raise FE_INVALID in a caller that traps it.
    if (std::isnan(x) || input.contains(x)) continue;
    if (std::isless(x, input.lo)) bits |= 1u << (2 * k);
    if (std::isgreater(x, input.hi)) bits |= 1u << (2 * k + 1);
  }
  return bits;
}

// Every evaluation entry point: checks the arguments, naming `function`, evaluates once for all the
// outputs asked, copies them out. MUFRIC_PARTIAL when some point got no answer.
int evaluate_into(const char* function, mufric_client* client, size_t n, const std::array<const double*, 4>& inputs,
                  double ci_level, const mufric_outputs& out, Required required) {
  const std::string name(function);
  if (client == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, name + ": client is NULL");
  if (out.counts) *out.counts = mufric_counts{};
  if (n == 0) {  // a step without contact: nothing to do, whatever the arrays are
    last_error.clear();
    return MUFRIC_OK;
  }
  if (required == Required::mu && out.mu == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, name + ": mu must not be NULL");
  if (required == Required::patch_std && out.patch_std == nullptr) {
    return fail(MUFRIC_INVALID_ARGUMENT, name + ": patch_std must not be NULL");
  }
  const bool want_interval = out.lo != nullptr || out.hi != nullptr;
  if (want_interval && !(ci_level > 0.0 && ci_level < 1.0)) {
    return fail(MUFRIC_INVALID_ARGUMENT, name + ": lo/hi requested but ci_level is not in (0, 1)");
  }
  if (out.patch_std != nullptr && !client->has_patch_scatter) {
    return fail(MUFRIC_INVALID_ARGUMENT, name + ": the model has no patch scatter (it was not trained by "
                                                "stochastic kriging on a dataset of independent draws)");
  }
  return guarded(function, [&] {
    const mufric::client::Block block{n, inputs[0], inputs[1], inputs[2], inputs[3]};
    const auto answer = evaluate_with_options(*client, block,
                                              {.std = out.std != nullptr,
                                               .ci_level = want_interval ? ci_level : 0.0,
                                               .gradient = false,
                                               .patch_std = out.patch_std != nullptr});
    // Copies only: the outputs of points without an answer are NaN or the caller's values, and
    // nothing here compares them (a caller trapping FE_INVALID would die on an ordered comparison with NaN).
    mufric_counts counts{};
    for (size_t i = 0; i < n; ++i) {
      if (out.mu) out.mu[i] = answer.mu[i];
      if (out.std) out.std[i] = answer.std[i];
      if (out.lo) out.lo[i] = answer.lo[i];
      if (out.hi) out.hi[i] = answer.hi[i];
      if (out.patch_std) out.patch_std[i] = answer.patch_std[i];
      if (out.status) out.status[i] = static_cast<int>(answer.status[i]);
      if (out.outside) out.outside[i] = outside_bits(*client, inputs, i);
      counts.extrapolated += answer.status[i] == mufric::PointStatus::extrapolated;
      counts.invalid += answer.status[i] == mufric::PointStatus::invalid_input;
      counts.out_of_box += answer.status[i] == mufric::PointStatus::out_of_box;
    }
    counts.range_clipped = static_cast<size_t>(answer.range_clipped);
    counts.fast_points = static_cast<size_t>(answer.fast_points);
    if (out.counts) *out.counts = counts;
    // the first point without an answer, or "" (the message of an answered block outside the box is
    // the C++ Answer's and the gRPC reply's, not an error)
    last_error = counts.invalid + counts.out_of_box > 0 ? answer.message : std::string();
    return counts.invalid + counts.out_of_box == 0 ? MUFRIC_OK : MUFRIC_PARTIAL;
  });
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
  const mufric_outputs outputs{mu, std, lo, hi, nullptr, status, nullptr, nullptr};
  return evaluate_into("mufric_evaluate", client, n, {contact_pressure, sliding_velocity, temperature, fibre_angle},
                       ci_level, outputs, Required::mu);
}

int mufric_evaluate_ex(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                       const double* temperature, const double* fibre_angle, double ci_level, double* mu, double* std,
                       double* lo, double* hi, int* status, unsigned* outside, mufric_counts* counts) {
  const mufric_outputs outputs{mu, std, lo, hi, nullptr, status, outside, counts};
  return evaluate_into("mufric_evaluate_ex", client, n, {contact_pressure, sliding_velocity, temperature, fibre_angle},
                       ci_level, outputs, Required::mu);
}

int mufric_evaluate_outputs(mufric_client* client, size_t n, const double* contact_pressure,
                            const double* sliding_velocity, const double* temperature, const double* fibre_angle,
                            double ci_level, const mufric_outputs* outputs) {
  if (outputs == nullptr) return fail(MUFRIC_INVALID_ARGUMENT, "mufric_evaluate_outputs: outputs must not be NULL");
  return evaluate_into("mufric_evaluate_outputs", client, n,
                       {contact_pressure, sliding_velocity, temperature, fibre_angle}, ci_level, *outputs,
                       Required::nothing);
}

int mufric_patch_std(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                     const double* temperature, const double* fibre_angle, double* patch_std, int* status) {
  const mufric_outputs outputs{nullptr, nullptr, nullptr, nullptr, patch_std, status, nullptr, nullptr};
  return evaluate_into("mufric_patch_std", client, n, {contact_pressure, sliding_velocity, temperature, fibre_angle},
                       0.0, outputs, Required::patch_std);
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
