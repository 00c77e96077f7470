#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <H5Cpp.h>

#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "temp_path.hpp"
#include "error_text.hpp"

namespace mufric {
namespace {

using test::temp_path;

Eigen::VectorXd values(std::initializer_list<double> list) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(list.size()));
  Eigen::Index i = 0;
  for (double x : list) v(i++) = x;
  return v;
}

using test::error_of;

TEST(DatasetFile, RoundTripKeepsFailuresAndTrainingSetSkipsThem) {
  Dataset d;
  d.inputs = default_friction_box();
  d.x.resize(3, 3);
  d.x << 400e6, 1.0, 500.0, 500e6, 1.5, 600.0, 600e6, 2.0, 700.0;
  d.mu = values({0.3, std::nan(""), 0.25});
  d.status = {0, 1, 0};
  d.failure_reason = {"", "Newton diverged at step 12", ""};
  d.diagnostics["wall_time_s"] = values({1.0, 2.0, 3.0});
  d.plan = d.x;
  d.source = "unit test";
  const std::string path = temp_path("d.h5");
  write_dataset(path, d);
  const Dataset r = read_dataset(path);
  EXPECT_EQ(r.x, d.x);
  EXPECT_EQ(r.status, d.status);
  EXPECT_EQ(r.failure_reason[1], "Newton diverged at step 12");
  EXPECT_EQ(r.diagnostics.at("wall_time_s"), d.diagnostics.at("wall_time_s"));
  EXPECT_EQ(r.inputs[0].name, "contact_pressure");
  const TrainingSet t = training_set(r, path);
  EXPECT_EQ(t.x.rows(), 2);
  EXPECT_EQ(t.mu(1), 0.25);
  EXPECT_EQ(t.source_hash.size(), 64u);
  std::filesystem::remove(path);
}

// Schema 2 carries each sample's standard error and a status for samples outside the model (a molten
// chip); schema-1 files (no /samples/mu_std) still load, with NaN standard errors and a note.
TEST(DatasetFile, StandardErrorsAndOutsideModelSamplesRoundTripAndOldFilesLoad) {
  Dataset d;
  d.inputs = default_friction_box();
  d.x.resize(3, 3);
  d.x << 400e6, 1.0, 500.0, 500e6, 1.5, 600.0, 1300e6, 0.4, 1100.0;
  d.mu = values({0.3, 0.28, 0.05});
  d.mu_std = values({0.004, 0.003, 0.01});
  d.status = {0, 0, static_cast<long long>(SampleStatus::outside_model)};
  d.failure_reason = {"", "", "the chip reached its melting temperature"};
  d.plan = d.x;
  const std::string path = temp_path("std.h5");
  write_dataset(path, d);
  const Dataset r = read_dataset(path);
  EXPECT_EQ(r.mu_std, d.mu_std);
  EXPECT_TRUE(r.note.empty());
  EXPECT_TRUE(r.outside_model(2));
  const TrainingSet t = training_set(r, path);
  EXPECT_EQ(t.x.rows(), 2);  // the molten sample is never trained on
  EXPECT_EQ(t.outside_model, 1);
  EXPECT_EQ(t.mu_std(1), 0.003);

  // The same file as schema 1 wrote it: no mu_std, schema_version 1.
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    file.unlink("/samples/mu_std");
    H5::Attribute version = file.openGroup("/").openAttribute("schema_version");
    const long long one = 1;
    version.write(H5::PredType::NATIVE_LLONG, &one);
  }
  const Dataset old = read_dataset(path);
  EXPECT_EQ(old.mu, d.mu);
  EXPECT_TRUE(old.mu_std.array().isNaN().all());
  EXPECT_NE(old.note.find("schema version 1"), std::string::npos) << old.note;
  EXPECT_EQ(training_set(old, path).mu_std.size(), 2);

  // Schema 3: the draws' design, each sample's seeds and each draw's μ round-trip; a schema-2 file
  // (none of them) reads as common draws of unknown per-draw μ.
  d.draws = DrawDesign::independent;
  d.tool_seed = {11, 12, -1};
  d.chip_seed = {21, 22, -1};
  d.draw_mu.resize(3, 2);
  d.draw_mu << 0.29, 0.31, 0.27, std::numeric_limits<double>::quiet_NaN(), 0.05, 0.05;
  write_dataset(path, d);
  const Dataset three = read_dataset(path);
  EXPECT_EQ(three.draws, DrawDesign::independent);
  EXPECT_EQ(three.tool_seed, d.tool_seed);
  EXPECT_EQ(three.chip_seed, d.chip_seed);
  ASSERT_EQ(three.draw_mu.cols(), 2);
  EXPECT_EQ(three.draw_mu(0, 1), 0.31);
  EXPECT_TRUE(std::isnan(three.draw_mu(1, 1)));
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    for (const char* name : {"/samples/tool_seed", "/samples/chip_seed", "/samples/draw_mu"}) file.unlink(name);
    file.openGroup("/plan").removeAttr("draws");
    H5::Attribute version = file.openGroup("/").openAttribute("schema_version");
    const long long two = 2;
    version.write(H5::PredType::NATIVE_LLONG, &two);
  }
  const Dataset two = read_dataset(path);
  EXPECT_EQ(two.draws, DrawDesign::unknown);
  EXPECT_TRUE(two.tool_seed.empty());
  EXPECT_EQ(two.draw_mu.cols(), 0);
  EXPECT_EQ(two.draw_mu.rows(), 3);
  EXPECT_EQ(two.mu, d.mu);

  // A status this build does not know is refused, naming the field and the row.
  d.status[1] = 7;
  write_dataset(path, d);
  const std::string m = error_of([&] { read_dataset(path); });
  EXPECT_NE(m.find("/samples/status"), std::string::npos) << m;
  EXPECT_NE(m.find("row 1"), std::string::npos) << m;
  std::filesystem::remove(path);
}

TEST(DatasetFile, CsvMayCarryStandardErrors) {
  const std::string path = temp_path("std.csv");
  std::ofstream(path) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu,mu_std\n800,120,500,0.3,0.004\n"
                         "900,60,25,0.4,0.002\n";
  const Dataset d = read_dataset(path);
  EXPECT_EQ(d.inputs.size(), 3u);
  EXPECT_DOUBLE_EQ(d.mu_std(1), 0.002);
  std::ofstream(path) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu,mu_std\n800,120,500,0.3,-1\n";
  const std::string m = error_of([&] { read_dataset(path); });
  EXPECT_NE(m.find("mu_std"), std::string::npos) << m;
  std::filesystem::remove(path);
}

TEST(DatasetFile, CsvWithUnitsConvertsToSi) {
  const std::string path = temp_path("d.csv");
  std::ofstream(path) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n800,120,500,0.3\n900,60,25,0.4\n";
  const Dataset d = read_dataset(path);
  EXPECT_DOUBLE_EQ(d.x(0, 0), 800e6);
  EXPECT_DOUBLE_EQ(d.x(0, 1), 2.0);
  EXPECT_DOUBLE_EQ(d.x(1, 2), 298.15);
  EXPECT_DOUBLE_EQ(d.inputs[2].lo, 298.15);
  std::filesystem::remove(path);
}

TEST(DatasetFile, CsvErrorsNameLineAndColumn) {
  const std::string path = temp_path("bad.csv");
  std::ofstream(path) << "contact_pressure[MPa],sliding_velocity[m/min],mu\n800,120,0.3\n900,nan,0.4\n";
  EXPECT_NE(error_of([&] { read_dataset(path); }).find("line 3, column 'sliding_velocity'"), std::string::npos);
  std::ofstream(path) << "contact_pressure,mu\n800,0.3\n";
  EXPECT_NE(error_of([&] { read_dataset(path); }).find("column 'contact_pressure' has no unit"), std::string::npos);
  std::ofstream(path) << "contact_pressure[psi],mu\n800,0.3\n";
  EXPECT_NE(error_of([&] { read_dataset(path); }).find("unknown unit 'psi'"), std::string::npos);
  std::filesystem::remove(path);
}

// A column that is not a model input (an id, a misspelt name) and a value outside the physical range
// are refused naming the column, and the line for a value (issue 30).
TEST(DatasetFile, CsvRefusesUnknownColumnsAndImpossibleValues) {
  const std::string path = temp_path("unknown.csv");
  std::ofstream(path) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],run_id,mu\n800,120,500,7,0.3\n";
  std::string m = error_of([&] { read_dataset(path); });
  EXPECT_NE(m.find("column 'run_id' is not a model input"), std::string::npos) << m;
  std::ofstream(path) << "pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n800,120,500,0.3\n";
  m = error_of([&] { read_dataset(path); });
  EXPECT_NE(m.find("column 'pressure' is not a model input"), std::string::npos) << m;
  std::ofstream(path) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n# a comment\n800,120,500,0.3\n"
                         "-500,120,500,0.3\n";
  m = error_of([&] { read_dataset(path); });
  EXPECT_NE(m.find("line 4, column 'contact_pressure': -500MPa is below 0MPa"), std::string::npos) << m;
  std::ofstream(path) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n800,120,-400,0.3\n";
  m = error_of([&] { read_dataset(path); });
  EXPECT_NE(m.find("line 2, column 'temperature': -400°C is below absolute zero"), std::string::npos) << m;
  std::filesystem::remove(path);
}

TEST(DatasetFile, NonFiniteConvergedSampleIsNamedByRow) {
  Dataset d;
  d.inputs = default_friction_box();
  d.x = h5::RowMatrix::Constant(2, 3, 500.0);
  d.x(1, 2) = std::nan("");
  d.mu = values({0.3, 0.3});
  d.status = {0, 0};
  d.failure_reason = {"", ""};
  const std::string path = temp_path("nan.h5");
  write_dataset(path, d);
  const std::string m = error_of([&] { training_set(read_dataset(path), path); });
  EXPECT_NE(m.find("sample row 1, input 'temperature'"), std::string::npos) << m;
  std::filesystem::remove(path);
}

TEST(DatasetFile, ModelFileIsNotADataset) {
  const std::string path = temp_path("x.h5");
  { H5::H5File f(path, H5F_ACC_TRUNC); }
  EXPECT_NE(error_of([&] { read_dataset(path); }).find("not a mufric dataset"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(DatasetFile, Sha256OfKnownVector) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

}  // namespace
}  // namespace mufric
