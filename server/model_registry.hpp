#pragma once
// The models a server answers with: every *.h5 of one directory, loaded when a file appears or
// changes. A reload swaps a shared pointer atomically, so requests in flight finish on the model they
// started with; a bad new file is refused and a deleted file is logged, and in both cases the loaded
// version keeps serving until a valid file of that name replaces it (an `rm`-then-`cp` deploy must
// not turn into NOT_FOUND answers). A model is retired only by restarting the server.
// A change is seen by each rescan from the file's identity (device, inode, size, modification and
// status-change times: a deploy that pins modification times still changes the status-change time,
// which no user can set) and, on a forced rescan (SIGHUP), by the SHA-256 of its content.
#include <filesystem>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "surrogate/core/friction_model.hpp"

namespace mufric::server {

// What identifies one version of a file without reading it (stat(2)).
struct FileIdentity {
  std::uintmax_t device = 0, inode = 0, size = 0;
  std::int64_t modified_ns = 0, status_changed_ns = 0;
  bool operator==(const FileIdentity&) const = default;
};

struct ServedModel {
  std::string name;     // file stem
  std::string version;  // first 16 hex digits of the file's SHA-256
  std::filesystem::path path;
  std::unique_ptr<FrictionModel> model;
};

class ModelRegistry {
 public:
  using Log = std::function<void(const std::string& level, const std::string& message)>;
  ModelRegistry(std::filesystem::path directory, Log log);

  enum class Rescan {
    kByIdentity,  // the periodic poll: a file whose identity is unchanged is not read
    kByContent,   // SIGHUP: every file is hashed, and one whose content differs is reloaded
  };
  // Rescans the directory: loads new and changed files; a file gone is logged once and its model
  // keeps serving. Returns the number of models loaded. Never throws for a bad model file; it is
  // logged and skipped.
  int refresh(Rescan rescan = Rescan::kByIdentity);

  std::shared_ptr<const ServedModel> find(const std::string& name) const;
  std::vector<std::shared_ptr<const ServedModel>> all() const;
  std::string names() const;  // "a, b, c" for error messages

 private:
  std::filesystem::path directory_;
  Log log_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const ServedModel>> models_;
  struct FileSeen {
    FileIdentity identity;
    std::string sha256;
    bool refused = false;  // not retried, not re-logged, until the file changes
  };
  std::map<std::string, FileSeen> seen_;  // the last version of each file looked at
  std::set<std::string> gone_;            // served models whose file is gone (logged once)
};

}  // namespace mufric::server
