#pragma once
// The orthogonal-cut analysis' files: a setup (JSON) naming the tests' CSV and what the analysis
// needs besides them, and the two tables it writes, every intermediate and the rows `mufric
// calibrate` reads. docs/new-pair.md shows a setup; data/cirp2022_ti6al4v_tin/orthogonal_cuts.json is one.
#include <string>
#include <vector>

#include "surrogate/reduction/orthogonal_cutting.hpp"
#include "surrogate/reduction/test_groups.hpp"
#include "surrogate/reduction/written_table.hpp"

namespace mufric {

// A setup as read: the analysis' numbers, the tests, and how to word and name the outputs.
struct OrthogonalCutStudy {
  OrthogonalCutSetup setup;
  std::vector<OrthogonalCut> cuts;
  std::string setup_path, tests_path;
  TestGroups groups;
  std::vector<std::string> provenance;     // the outputs' first comment lines, without "# "
  std::string analysis_file = "rake_face_analysis.csv";
  std::string calibration_file = "rake_face_mu.csv";  // "{}" is the group's value
};

// Reads the setup and its tests (the tests' path relative to the setup's folder). Errors name the
// setup's field or the tests' file, line and column.
OrthogonalCutStudy read_orthogonal_cut_study(const std::string& setup_path);

// The analysis table (every group, every intermediate) and the calibration table of each calibrated
// group.
std::vector<WrittenTable> orthogonal_cut_tables(const OrthogonalCutStudy& study, const std::vector<RakeFaceEstimate>& results);

// One line per speed for a person: μ, p, v, T with their SDs, l_c/h, the edge forces and Birge scales.
std::string orthogonal_cut_summary(const OrthogonalCutStudy& study, const std::vector<RakeFaceEstimate>& results);

}  // namespace mufric
