#pragma once
// Small pieces of the English every message is written in, so "1 files" and "a angle" do not reach a user.
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace mufric {

// "1 file", "3 files", "0 files".
inline std::string count_of(long long n, std::string_view singular, std::string_view plural) {
  return std::to_string(n) + " " + std::string(n == 1 ? singular : plural);
}

// "a pressure", "an angle": the indefinite article by the word's first letter, which is right for
// the words messages put after it (quantity kinds, input names); not for "an hour" or "a unit".
inline std::string with_article(std::string_view word) {
  const bool vowel = !word.empty() && std::string_view("aeiouAEIOU").find(word.front()) != std::string_view::npos;
  return std::string(vowel ? "an " : "a ") + std::string(word);
}

// "42s", "3m07s", "2h05m": a duration as a person reads it ("?" when not finite).
inline std::string duration_text(double seconds) {
  char text[32];
  if (!std::isfinite(seconds)) return "?";
  if (seconds < 90) {
    std::snprintf(text, sizeof text, "%.0fs", seconds);
  } else if (seconds < 5400) {
    std::snprintf(text, sizeof text, "%.0fm%02.0fs", std::floor(seconds / 60), std::fmod(seconds, 60.0));
  } else {
    std::snprintf(text, sizeof text, "%.0fh%02.0fm", std::floor(seconds / 3600), std::fmod(seconds / 60, 60.0));
  }
  return text;
}

// How many single-character insertions, deletions, substitutions or adjacent swaps turn a into b.
// printf into a string of whatever length it takes, for messages made of figures.
__attribute__((format(printf, 1, 2))) std::string text_printf(const char* pattern, ...);

size_t edit_distance(std::string_view a, std::string_view b);

// The candidate fewest edits from word (the first of equals), if at most most_edits away; "" if none is.
std::string_view nearest_word(std::string_view word, const std::vector<std::string_view>& candidates, size_t most_edits);

}  // namespace mufric
