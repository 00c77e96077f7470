#include "campaign/learning_log.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>

#include "common/files.hpp"
#include "common/uncertain_log.hpp"

namespace mufric {

namespace fs = std::filesystem;
using nlohmann::json;


namespace {

long long file_id_of(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<long long>(st.st_ino) : 0;
}

// The whole lines of `text` after `offset` (from the line after the header when offset is inside it or
// past the end), and the offset after them.
std::pair<std::string, long long> lines_after(const std::string& text, long long offset) {
  const auto header_end = text.find('\n');
  if (header_end == std::string::npos) return {"", offset};
  const long long size = static_cast<long long>(text.size());
  const long long start = offset > size || offset <= static_cast<long long>(header_end) ? static_cast<long long>(header_end) + 1 : offset;
  const long long end = static_cast<long long>(text.rfind('\n')) + 1;
  if (end <= start) return {"", start};
  return {text.substr(static_cast<size_t>(start), static_cast<size_t>(end - start)), end};
}

}  // namespace

NewLogRows read_new_log_rows(const std::string& path, long long offset, long long file_id) {
  NewLogRows out;
  out.end_offset = offset;
  out.file_id = file_id;
  std::string rows, header;
  const long long current_id = file_id_of(path);
  if (file_id != 0 && current_id != file_id) {  // renamed since the last look
    const std::string rotated = rotated_log_path(path);
    const auto old_text = file_id_of(rotated) == file_id ? read_whole_file(rotated) : std::nullopt;
    if (old_text) {
      rows = lines_after(*old_text, offset).first;
      header = old_text->substr(0, old_text->find('\n') + 1);
    }
    offset = 0;  // the new file from its start
  }
  const auto text = read_whole_file(path);
  if (text && text->find('\n') != std::string::npos) {
    auto [more, end] = lines_after(*text, offset);
    rows += more;
    header = text->substr(0, text->find('\n') + 1);
    out.end_offset = end;
    out.file_id = current_id;
  }
  if (header.empty()) return out;
  out.csv = header + rows;
  out.rows = static_cast<long long>(std::count(rows.begin(), rows.end(), '\n'));
  return out;
}

long long logged_query_count(const std::string& log_path) {
  fs::path p(log_path);
  p.replace_extension(".outside.json");
  const auto text = read_whole_file(p.string());
  if (!text) return -1;
  try {
    return json::parse(*text).at("queries").get<long long>();
  } catch (const std::exception&) {
    return -1;
  }
}

}  // namespace mufric
