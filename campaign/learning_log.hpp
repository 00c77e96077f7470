#pragma once
// The learner's intake (campaign/learning.hpp, step 1): the rows the server logged since the last
// round (`serve --log-uncertain`, common/uncertain_log.hpp) and the model's query count beside them.
#include <string>

namespace mufric {

// The rows the server appended since `offset` (whole lines only: a line being written is left for
// the next round), as a CSV with the file's header; the new offset and the file it is in. The server
// renames a full log to NAME.csv.1 and begins a new one (common/uncertain_log.hpp): when the file read
// last time (`file_id`, its inode; 0: not known) is now the renamed one, its rest is read first, then
// the new file from its start. A log shorter than the offset in the same file was started afresh by
// an operator: it is read from its start.
struct NewLogRows {
  std::string csv;  // header + the new lines ("" when the log does not exist)
  long long rows = 0;
  long long end_offset = 0;
  long long file_id = 0;
};
NewLogRows read_new_log_rows(const std::string& path, long long offset, long long file_id);

// The model's query count from the log's NAME.outside.json beside it (−1 when absent or unreadable:
// the server writes it at most once a second, atomically).
long long logged_query_count(const std::string& log_path);

}  // namespace mufric
