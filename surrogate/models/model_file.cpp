#include "surrogate/models/model_file.hpp"

#include <memory>

#include <omp.h>

#include "common/error.hpp"
#include "common/isolation.hpp"
#include "common/version.hpp"
#include "surrogate/models/model_kinds.hpp"

namespace mufric {

void save_model(const std::string& path, const FrictionModel& model) {
  h5::Writer out(path);
  out.string_attribute("/", "format", kModelFormat);
  out.int_attribute("/", "schema_version", kModelSchemaVersion);
  out.string_attribute("/", "kind", std::string(model.kind()));
  out.string_attribute("/", "code_version", code_version());
  out.string_attribute("/", "created_utc", utc_timestamp());
  write_input_space(out, model.inputs());
  out.string_attribute("/", "extrapolation", std::string(to_string(model.default_extrapolation())));
  out.double_attribute("/", "mu_min", model.mu_min());
  out.double_attribute("/", "mu_max", model.mu_max());
  model.write(out);
  out.commit();
}

namespace {
// The policy for points outside the box and μ's physical range (files before them: the defaults).
void read_extrapolation(const h5::Reader& in, FrictionModel& model) {
  if (in.has_attribute("/", "extrapolation")) {
    try {
      model.set_default_extrapolation(extrapolation_from_string(in.string_attribute("/", "extrapolation")));
    } catch (const Error& e) {
      in.fail("/", std::string("attribute extrapolation: ") + e.what());
    }
  }
  if (in.has_attribute("/", "mu_min") || in.has_attribute("/", "mu_max")) {
    try {
      model.set_mu_range(in.double_attribute("/", "mu_min"), in.double_attribute("/", "mu_max"));
    } catch (const Error& e) {
      in.fail("/", std::string("attributes mu_min, mu_max: ") + e.what());
    }
  }
}

std::unique_ptr<FrictionModel> read_model(const std::string& path) {
  const h5::Reader in(path, "model");
  in.require_format(kModelFormat, kOldestReadableModelSchema, kModelSchemaVersion, "mufric model");
  InputSpace inputs = read_input_space(in);
  const std::string kind = in.string_attribute("/", "kind");
  const ModelKindEntry* entry = find_model_kind(kind);
  if (entry == nullptr) in.fail("/", "unknown model kind '" + kind + "' (known: " + model_kind_names() + ")");
  try {
    std::unique_ptr<FrictionModel> model = entry->read(in, std::move(inputs));
    read_extrapolation(in, *model);
    return model;
  } catch (const H5::Exception& e) {
    in.fail("/" + kind, "unreadable (" + e.getDetailMsg() + ")");
  } catch (const Error& e) {
    const std::string message = e.what();
    if (message.rfind("model '", 0) == 0) throw;
    in.fail("/" + kind, message);
  }
}
}  // namespace

std::unique_ptr<FrictionModel> load_model(const std::string& path) {
  try {
    return read_model(path);
  } catch (const H5::Exception& e) {  // what the field-naming reads do not translate themselves
    throw Error("model '" + path + "': unreadable HDF5 (" + e.getDetailMsg() + ")");
  }
}

std::unique_ptr<FrictionModel> load_model_isolated(const std::string& path, const IsolationLimits& limits) {
  const IsolatedCopy copy = rewrite_in_child(path, "model", [](const std::string& original, const std::string& rewritten) {
    // The child of a threaded parent runs on one thread: an OpenMP team there would wait for the
    // parent's pool threads, which fork() does not copy (libgomp is not fork-safe), so a model kind
    // that evaluates while it loads (a calibrated model's likelihood factors) would stall.
    omp_set_num_threads(1);
    save_model(rewritten, *load_model(original));
  }, limits);
  return load_model(copy.path());
}

}  // namespace mufric
