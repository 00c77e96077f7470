#pragma once
// The tests of a reduction may be analysed apart by a key column (the inclination of a cut, a
// lubricant's number): the column, how its groups are worded and which groups' rows go to calibrate.
#include <algorithm>
#include <string>
#include <vector>

namespace mufric {

struct TestGroups {
  std::string column;                // the tests' column (empty: one group, 0)
  std::string header;                // its header cell as the file gives it ("inclination_angle[deg]")
  std::string label = "All tests";   // "Inclination {} deg": {} is the group's value as the file gives it
  std::vector<double> calibrated;    // the groups whose rows go to calibrate (empty: every group)

  bool calibrates(double group) const {
    return calibrated.empty() || std::find(calibrated.begin(), calibrated.end(), group) != calibrated.end();
  }
  // The tables' leading cell of the header and of a row: "inclination_angle[deg]," and "6,", or nothing.
  std::string header_cell() const { return header.empty() ? std::string() : header + ","; }
};

// The groups of a reduction's results (each with a `group`), in the order they first appear.
template <typename Results>
std::vector<double> groups_in_order(const Results& results) {
  std::vector<double> groups;
  for (const auto& r : results)
    if (std::find(groups.begin(), groups.end(), r.group) == groups.end()) groups.push_back(r.group);
  return groups;
}

}  // namespace mufric
