#pragma once
// Model files (docs/formats.md, "The model file"): one HDF5 file per model, self-describing and versioned.
//   /  attributes format = "mufric-model", schema_version, kind (gp | mlr | coulomb | calibrated),
//      code_version, created_utc;   /inputs (names, SI units, box);   /<kind> the model's own data.
// Loading validates everything and refuses a corrupt or incompatible file naming the field.
#include <memory>
#include <string>
#include <vector>

#include "common/isolation.hpp"
#include "surrogate/core/friction_model.hpp"

namespace mufric {

// Version 2 added a GP's optional /gp/known_noise and its micro_std_error attribute (the micro-model's
// scatter, part of the interval); version-1 files still load (no scatter: the interval as before).
// Version 3 added a GP's optional /gp/fast_evaluator (cells, values, bounds, sha256): the certified
// fast evaluator; older files load without one (`mufric upgrade` adds it).
// Version 4 added a GP's interval attribute (new-run, shared-scatter or mean-over-draws) and its
// optional /gp/patch_scatter (a GP of the same layout for the log per-draw variance of μ, issue 33);
// older files load with the interval their micro_std_error implies and no patch scatter.
// Version 5 added kind "calibrated" (/calibrated: the campaign's GP, the measurements, the posterior
// samples and their summary, an optional fast evaluator; surrogate/calibration/calibrated_model.hpp); files of
// the other kinds are unchanged.
inline constexpr long long kModelSchemaVersion = 5;
inline constexpr long long kOldestReadableModelSchema = 1;
inline constexpr const char* kModelFormat = "mufric-model";

// Writes atomically (temporary file + rename).
void save_model(const std::string& path, const FrictionModel& model);
std::unique_ptr<FrictionModel> load_model(const std::string& path);
// load_model for a file that may be corrupt or hostile: parsed and validated in a child process
// (common/isolation.hpp), then read back from the copy the child wrote. A file that crashes or hangs
// the HDF5 library becomes an Error naming it. For the CLI and the server, not for a meso code.
std::unique_ptr<FrictionModel> load_model_isolated(const std::string& path, const IsolationLimits& limits = {});

// The models shipped with mufric (models/*.h5 of the source tree, installed to
// <prefix>/share/mufric/models): $MUFRIC_MODELS_DIR if set, else the first that exists of
// share/mufric/models of the prefix this code was loaded from (libmufric.so's, or the executable's it
// is linked into), the configured install prefix's, and the source tree's (only for code running
// from its build tree); "" when there is none.
std::string shipped_models_directory();
// The stems of the shipped models ("dry_default", ...), sorted; empty without a directory.
std::vector<std::string> shipped_model_names();

// "file:///abs/model.h5", "file://rel/model.h5" or a plain path → the path; other schemes throw.
// A bare name (no '/') that is not a file here names a shipped model: "dry_default" (or
// "dry_default.h5") → <shipped directory>/dry_default.h5; a bare name without ".h5" that is neither
// throws, listing the shipped models.
std::string model_path_from_uri(const std::string& uri);

}  // namespace mufric
