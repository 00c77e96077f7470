#include "server/model_registry.hpp"

#include <exception>
#include <set>

#include "common/dataset_file.hpp"
#include "surrogate/model_file.hpp"

namespace mufric::server {
namespace {
constexpr size_t kVersionDigits = 16;
}

ModelRegistry::ModelRegistry(std::filesystem::path directory, Log log)
    : directory_(std::move(directory)), log_(std::move(log)) {}

int ModelRegistry::refresh() {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::set<std::string> present;
  int changed = 0;
  for (const auto& entry : fs::directory_iterator(directory_, ec)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".h5") continue;
    const std::string name = entry.path().stem().string();
    present.insert(name);
    const auto modified = entry.last_write_time(ec);
    const auto size = entry.file_size(ec);
    {
      std::lock_guard lock(mutex_);
      const auto it = models_.find(name);
      if (it != models_.end() && it->second->modified == modified && it->second->size == size) continue;
      const auto bad = refused_.find(name);
      if (bad != refused_.end() && bad->second == std::make_pair(modified, size)) continue;
    }
    auto served = std::make_shared<ServedModel>();
    served->name = name;
    served->path = entry.path();
    served->modified = modified;
    served->size = size;
    try {
      served->version = sha256_file(entry.path().string()).substr(0, kVersionDigits);
      served->model = load_model_isolated(entry.path().string());
    } catch (const std::exception& e) {
      log_("warning", "refused model file " + entry.path().string() + ": " + e.what() +
                          " (the previous version, if any, keeps serving)");
      std::lock_guard lock(mutex_);
      refused_[name] = {modified, size};
      continue;
    }
    log_("info", "serving model '" + name + "' version " + served->version + " (" + std::string(served->model->kind()) + ")");
    std::lock_guard lock(mutex_);
    refused_.erase(name);
    models_[name] = std::move(served);
    ++changed;
  }
  if (ec) log_("error", "cannot scan " + directory_.string() + ": " + ec.message());
  std::lock_guard lock(mutex_);
  for (auto it = models_.begin(); it != models_.end();) {
    if (present.count(it->first) == 0 && !ec) {
      log_("info", "model '" + it->first + "' removed (file gone)");
      it = models_.erase(it);
      ++changed;
    } else {
      ++it;
    }
  }
  return changed;
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
