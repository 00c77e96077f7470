#pragma once
// The models a server answers with: every *.h5 of one directory, reloaded when a file appears,
// changes or disappears. A reload swaps a shared pointer atomically, so requests in flight finish
// on the model they started with, and a bad new file is refused while the old model keeps serving.
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "surrogate/friction_model.hpp"

namespace mufric::server {

struct ServedModel {
  std::string name;     // file stem
  std::string version;  // first 16 hex digits of the file's SHA-256
  std::filesystem::path path;
  std::filesystem::file_time_type modified;
  std::uintmax_t size = 0;
  std::unique_ptr<FrictionModel> model;
};

class ModelRegistry {
 public:
  using Log = std::function<void(const std::string& level, const std::string& message)>;
  ModelRegistry(std::filesystem::path directory, Log log);

  // Rescans the directory: loads new and changed files, drops removed ones. Returns the number of
  // models changed. Never throws for a bad model file; it is logged and skipped.
  int refresh();

  std::shared_ptr<const ServedModel> find(const std::string& name) const;
  std::vector<std::shared_ptr<const ServedModel>> all() const;
  std::string names() const;  // "a, b, c" for error messages

 private:
  std::filesystem::path directory_;
  Log log_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const ServedModel>> models_;
  // Files refused at this (time, size): not retried, not re-logged, until they change.
  std::map<std::string, std::pair<std::filesystem::file_time_type, std::uintmax_t>> refused_;
};

}  // namespace mufric::server
