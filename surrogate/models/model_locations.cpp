// Where model files are: the shipped models' folder and the URIs a client or command names a model by
// (declared in model_file.hpp).
#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "common/error.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric {

namespace {

// The file this code was loaded from: libmufric.so for a meso code linked with -lmufric, else the
// executable it is linked into statically (dladdr of a function of this library).
std::filesystem::path file_holding_this_code() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&shipped_models_directory), &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code ignored;
  const std::filesystem::path path = std::filesystem::canonical(info.dli_fname, ignored);
  return ignored ? std::filesystem::path(info.dli_fname) : path;
}

// <prefix>/share/mufric/models for a file in <prefix>/bin, <prefix>/lib or <prefix>/lib/<multiarch>.
std::string models_beside(const std::filesystem::path& file) {
  std::error_code ignored;
  std::filesystem::path dir = file.parent_path();
  for (int up = 0; up < 2 && !dir.empty(); ++up, dir = dir.parent_path()) {
    const auto candidate = dir.parent_path() / "share/mufric/models";
    if (std::filesystem::is_directory(candidate, ignored)) return candidate.string();
  }
  return {};
}

bool is_inside(const std::filesystem::path& file, const std::filesystem::path& dir) {
  const auto relative = file.lexically_relative(dir);
  return !relative.empty() && *relative.begin() != "..";
}

}  // namespace

std::string shipped_models_directory() {
  namespace fs = std::filesystem;
  if (const char* set = std::getenv("MUFRIC_MODELS_DIR"); set != nullptr && *set != '\0') return set;
  std::error_code ignored;
  // From where this code lives, not from the calling executable: a meso code linked against an
  // installed libmufric.so finds <its prefix>/share/mufric/models wherever the meso code itself is
  // (issue 49: it found the build's source tree instead). Then the prefix configured at build time;
  // the source tree only for code running from its own build tree, so that an installed copy never
  // reads models from a source tree that may be gone or newer.
  const fs::path holder = file_holding_this_code();
  if (!holder.empty()) {
    if (std::string beside = models_beside(holder); !beside.empty()) return beside;
  }
  if (fs::is_directory(MUFRIC_INSTALLED_MODELS_DIR, ignored)) return MUFRIC_INSTALLED_MODELS_DIR;
  if ((holder.empty() || is_inside(holder, MUFRIC_BUILD_DIR)) && fs::is_directory(MUFRIC_SOURCE_MODELS_DIR, ignored)) {
    return MUFRIC_SOURCE_MODELS_DIR;
  }
  return {};
}

std::vector<std::string> shipped_model_names() {
  namespace fs = std::filesystem;
  std::vector<std::string> names;
  const std::string dir = shipped_models_directory();
  std::error_code error;
  if (dir.empty() || !fs::is_directory(dir, error)) return names;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    if (entry.path().extension() == ".h5") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

namespace {

// A bare name (no '/'): the shipped model of that name, if there is one. Without ".h5" the shipped
// model wins over anything of that name here (a folder or file named dry_default in the working
// directory shadowed it with "not an HDF5 file"; a local file is ./dry_default); with ".h5" a
// regular file here comes first.
std::string shipped_model_path(const std::string& name) {
  namespace fs = std::filesystem;
  std::error_code ignored;
  if (name.empty() || name.find('/') != std::string::npos) return name;
  const bool has_extension = name.ends_with(".h5");
  if (has_extension && fs::is_regular_file(name, ignored)) return name;
  if (!has_extension && fs::exists(name, ignored)) {
    const std::string dir = shipped_models_directory();
    const bool shipped = !dir.empty() && fs::is_regular_file(fs::path(dir) / (name + ".h5"), ignored);
    if (!shipped) return name;
  }
  const std::string stem = has_extension ? name.substr(0, name.size() - 3) : name;
  const std::string dir = shipped_models_directory();
  if (const fs::path shipped = fs::path(dir) / (stem + ".h5"); !dir.empty() && fs::is_regular_file(shipped, ignored)) {
    return shipped.string();
  }
  if (has_extension) return name;  // a file name: opening it says it is missing
  std::string shipped;
  for (const auto& n : shipped_model_names()) shipped += (shipped.empty() ? "" : ", ") + n;
  throw Error("model '" + name + "': no such file here, and no shipped model of that name (" +
              (dir.empty() ? std::string("no shipped models found; set MUFRIC_MODELS_DIR")
                           : "shipped, in " + dir + ": " + (shipped.empty() ? std::string("none") : shipped)) +
              ")");
}

}  // namespace

std::string model_path_from_uri(const std::string& uri) {
  const std::string file_scheme = "file://";
  if (uri.rfind(file_scheme, 0) == 0) return shipped_model_path(uri.substr(file_scheme.size()));
  const auto scheme_end = uri.find("://");
  if (scheme_end != std::string::npos) {
    throw Error("model URI '" + uri + "': scheme '" + uri.substr(0, scheme_end) +
                "' is not handled here; use file:///path/model.h5, a plain path or a shipped model's name");
  }
  return shipped_model_path(uri);
}

}  // namespace mufric
