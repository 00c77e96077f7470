#include "server/model_registry.hpp"

#include <sys/stat.h>

#include <exception>
#include <optional>

#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/isolation.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric::server {
namespace {
constexpr std::int64_t kNanosecondsPerSecond = 1'000'000'000;

std::optional<FileIdentity> identity_of(const std::filesystem::path& path) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) return std::nullopt;
  const auto ns = [](const timespec& t) { return std::int64_t(t.tv_sec) * kNanosecondsPerSecond + t.tv_nsec; };
  return FileIdentity{std::uintmax_t(status.st_dev), std::uintmax_t(status.st_ino), std::uintmax_t(status.st_size),
                      ns(status.st_mtim), ns(status.st_ctim)};
}
}  // namespace

ModelRegistry::ModelRegistry(std::filesystem::path directory, Log log)
    : directory_(std::move(directory)), log_(std::move(log)) {}

int ModelRegistry::refresh(Rescan rescan) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::set<std::string> present;
  int loaded = 0;
  for (const auto& entry : fs::directory_iterator(directory_, ec)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".h5") continue;
    const std::string name = entry.path().stem().string();
    const auto identity = identity_of(entry.path());
    if (!identity) continue;  // gone between the listing and stat(): the next rescan sees it
    present.insert(name);
    {
      std::lock_guard lock(mutex_);
      if (gone_.erase(name) > 0) log_("info", "model '" + name + "': file " + entry.path().string() + " is back");
      const auto seen = seen_.find(name);
      if (rescan == Rescan::kByIdentity && seen != seen_.end() && seen->second.identity == *identity) continue;
    }
    std::string sha256;
    try {
      sha256 = sha256_file(entry.path().string());
    } catch (const std::exception& e) {
      log_("warning", "cannot read model file " + entry.path().string() + ": " + e.what());
      continue;
    }
    {
      // Same bytes under a new identity (touched, copied over itself, renamed in place): nothing to load.
      std::lock_guard lock(mutex_);
      auto& seen = seen_[name];
      const bool same_content = seen.sha256 == sha256 && (seen.refused || models_.count(name) > 0);
      seen.identity = *identity;
      if (same_content) continue;
      seen.sha256 = sha256;
    }
    auto served = std::make_shared<ServedModel>();
    served->name = name;
    served->path = entry.path();
    served->version = sha256.substr(0, kFileVersionDigits);  // file_version, from the hash in hand
    try {
      served->model = load_model_isolated(entry.path().string());
      if (const std::string why = servable_inputs_violation(input_names(served->model->inputs())); !why.empty()) {
        throw Error("not served: " + why);
      }
    } catch (const CheckerUnavailable& e) {
      // Nothing is known of the file: forget it was seen, so that the next scan (the poller's, or a
      // SIGHUP's) checks it again.
      log_("warning", "could not check model file " + entry.path().string() + ": " + e.what() +
                          " (retried at the next scan; the previous version, if any, keeps serving)");
      std::lock_guard lock(mutex_);
      seen_.erase(name);
      continue;
    } catch (const std::exception& e) {
      log_("warning", "refused model file " + entry.path().string() + ": " + e.what() +
                          " (the previous version, if any, keeps serving)");
      std::lock_guard lock(mutex_);
      seen_[name].refused = true;
      continue;
    }
    log_("info", "serving model '" + name + "' version " + served->version + " (" + std::string(served->model->kind()) + ")");
    std::lock_guard lock(mutex_);
    seen_[name].refused = false;
    models_[name] = std::move(served);
    ++loaded;
  }
  if (ec) {
    log_("error", "cannot scan " + directory_.string() + ": " + ec.message());
    return loaded;
  }
  std::lock_guard lock(mutex_);
  for (const auto& [name, model] : models_) {
    if (present.count(name) > 0 || !gone_.insert(name).second) continue;
    log_("warning", "model '" + name + "': file " + model->path.string() + " is gone; version " + model->version +
                        " keeps serving until a valid file of that name replaces it (restart the server to retire it)");
  }
  for (auto it = seen_.begin(); it != seen_.end();) {
    // A refused file that is gone is forgotten; a served one is remembered so that a file with
    // the same bytes coming back is not reloaded.
    it = present.count(it->first) == 0 && models_.count(it->first) == 0 ? seen_.erase(it) : std::next(it);
  }
  return loaded;
}

std::shared_ptr<const ServedModel> ModelRegistry::find(const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = models_.find(name);
  return it == models_.end() ? nullptr : it->second;
}

std::vector<std::shared_ptr<const ServedModel>> ModelRegistry::all() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<const ServedModel>> list;
  for (const auto& [name, model] : models_) list.push_back(model);
  return list;
}

std::string ModelRegistry::names() const {
  std::lock_guard lock(mutex_);
  std::string list;
  for (const auto& [name, model] : models_) list += (list.empty() ? "" : ", ") + name;
  return list.empty() ? "(none)" : list;
}

}  // namespace mufric::server
