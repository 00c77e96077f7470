#include "common/wording.hpp"

#include <cstdarg>
#include <cstdio>

#include <algorithm>
#include <vector>

namespace mufric {

// Optimal string alignment distance (Wagner & Fischer 1974, J. ACM 21:168, with Damerau's adjacent
// swap): "predcit" is 1 from "predict".
std::string text_printf(const char* pattern, ...) {
  va_list arguments, measuring;
  va_start(arguments, pattern);
  va_copy(measuring, arguments);
  const int length = std::vsnprintf(nullptr, 0, pattern, measuring);
  va_end(measuring);
  std::string text(length > 0 ? static_cast<size_t>(length) : 0, '\0');
  if (length > 0) std::vsnprintf(text.data(), text.size() + 1, pattern, arguments);
  va_end(arguments);
  return text;
}

size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

std::string_view nearest_word(std::string_view word, const std::vector<std::string_view>& candidates, size_t most_edits) {
  std::string_view nearest;
  size_t nearest_distance = most_edits + 1;
  for (const std::string_view candidate : candidates) {
    const size_t distance = edit_distance(word, candidate);
    if (distance < nearest_distance) nearest = candidate, nearest_distance = distance;
  }
  return nearest;
}

}  // namespace mufric
