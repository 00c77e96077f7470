// Model files: bit-for-bit round trips; corrupt, truncated and incompatible files are refused by name.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/error.hpp"
#include "corrupt_files.hpp"
#include "gp_test_data.hpp"
#include "surrogate/laws/empirical_laws.hpp"
#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/models/model_file.hpp"
#include "temp_path.hpp"

namespace mufric {
namespace {

using test::temp_path;

bool bitwise_equal(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

std::string load_error(const std::string& path) {
  try {
    load_model(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

GaussianProcess small_gp(Eigen::Index n = 60) {
  GpTrainingOptions options;
  options.restarts = 1;
  return train_gaussian_process(test::smooth_training_set(n, 2), options);
}

TEST(ModelFile, GaussianProcessRoundTripsBitForBit) {
  const GaussianProcess gp = small_gp();
  const std::string path = temp_path("gp.h5");
  save_model(path, gp);
  const auto loaded = load_model(path);
  ASSERT_EQ(loaded->kind(), "gp");
  const auto& a = gp.state();
  const auto& b = dynamic_cast<const GaussianProcess&>(*loaded).state();
  EXPECT_TRUE(bitwise_equal(a.x_train, b.x_train));
  EXPECT_TRUE(bitwise_equal(a.y_train, b.y_train));
  EXPECT_TRUE(bitwise_equal(a.alpha, b.alpha));
  EXPECT_TRUE(bitwise_equal(a.cholesky, b.cholesky));
  EXPECT_TRUE(bitwise_equal(a.hyper.length_scales, b.hyper.length_scales));
  EXPECT_EQ(std::memcmp(&a.hyper.signal_variance, &b.hyper.signal_variance, sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(&a.hyper.noise_variance, &b.hyper.noise_variance, sizeof(double)), 0);
  EXPECT_EQ(a.y_mean, b.y_mean);
  EXPECT_EQ(a.y_scale, b.y_scale);
  EXPECT_EQ(a.summary.log_marginal_likelihood, b.summary.log_marginal_likelihood);
  const TrainingSet q = test::smooth_training_set(300, 9);
  const EvaluationRequest what{.std = true, .ci_level = 0.95, .gradient = true};
  const Evaluation e1 = gp.evaluate(q.x, what), e2 = loaded->evaluate(q.x, what);
  EXPECT_TRUE(bitwise_equal(e1.mu, e2.mu));
  EXPECT_TRUE(bitwise_equal(e1.std, e2.std));
  EXPECT_TRUE(bitwise_equal(e1.gradient, e2.gradient));
  std::filesystem::remove(path);
}

TEST(ModelFile, LargeModelWithoutStoredFactorIsRefactorisedOnLoad) {
  GpTrainingOptions options;
  options.optimise = false;
  options.initial.length_scales = Eigen::Vector3d(0.7, 0.7, 0.7);
  options.initial.noise_variance = 1e-6;
  const GaussianProcess gp = train_gaussian_process(test::smooth_training_set(GaussianProcess::kStoreCholeskyUpTo + 1, 4), options);
  const std::string path = temp_path("big.h5");
  save_model(path, gp);
  const auto loaded = load_model(path);
  const TrainingSet q = test::smooth_training_set(50, 9);
  const Evaluation e1 = gp.evaluate(q.x, {.std = true}), e2 = loaded->evaluate(q.x, {.std = true});
  EXPECT_LT((e1.mu - e2.mu).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((e1.std - e2.std).cwiseAbs().maxCoeff(), 1e-9);
  std::filesystem::remove(path);
}

TEST(ModelFile, LawsRoundTrip) {
  const std::string path = temp_path("law.h5");
  save_model(path, MlrLaw::seed001_table4());
  const auto law = load_model(path);
  ASSERT_EQ(law->kind(), "mlr");
  const auto& rows = dynamic_cast<const MlrLaw&>(*law).rows();
  ASSERT_EQ(rows.size(), 8u);
  EXPECT_EQ(rows[4].beta1_per_m_min, 0.013133);
  save_model(path, CoulombLaw(0.37));
  EXPECT_EQ(dynamic_cast<const CoulombLaw&>(*load_model(path)).mu(), 0.37);
  std::filesystem::remove(path);
}

TEST(ModelFile, MissingFileIsNamed) {
  EXPECT_NE(load_error("/nonexistent/model.h5").find("/nonexistent/model.h5': no such file"), std::string::npos);
}

TEST(ModelFile, TruncatedFileIsRefused) {
  const std::string path = temp_path("trunc.h5");
  save_model(path, small_gp());
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
  const std::string message = load_error(path);
  EXPECT_FALSE(message.empty());
  EXPECT_NE(message.find(path), std::string::npos);
  std::filesystem::remove(path);
}

TEST(ModelFile, TextFileIsNotHdf5) {
  const std::string path = temp_path("text.h5");
  std::ofstream(path) << "contact_pressure,mu\n1,2\n";
  EXPECT_NE(load_error(path).find("not an HDF5 file"), std::string::npos);
  std::filesystem::remove(path);
}

// Overwrites a dataset of an existing file in place, as a flipped bit or a bad tool would.
void overwrite_doubles(const std::string& path, const std::string& dataset, const std::vector<double>& values) {
  H5::H5File file(path, H5F_ACC_RDWR);
  file.openDataSet(dataset).write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

TEST(ModelFile, CorruptAlphaIsRefusedNamingTheField) {
  const std::string path = temp_path("alpha.h5");
  const GaussianProcess gp = small_gp();
  save_model(path, gp);
  std::vector<double> alpha(gp.state().alpha.data(), gp.state().alpha.data() + gp.state().alpha.size());
  alpha[7] *= 1.001;
  overwrite_doubles(path, "/gp/alpha", alpha);
  EXPECT_NE(load_error(path).find("/gp/alpha"), std::string::npos);
  std::filesystem::remove(path);
}

// Regression: one α entry blown up by a flipped exponent bit (0.57 -> ~1e180) inflated the norms the
// consistency checks were scaled by, so the file was served and answered mu ~ 1e182 with status OK.
TEST(ModelFile, HugeAlphaEntryIsRefused) {
  const std::string path = temp_path("alpha_huge.h5");
  const GaussianProcess gp = small_gp();
  save_model(path, gp);
  for (const double bad : {1e180, -1e30, 1e6}) {
    std::vector<double> alpha(gp.state().alpha.data(), gp.state().alpha.data() + gp.state().alpha.size());
    alpha[21] = bad;
    overwrite_doubles(path, "/gp/alpha", alpha);
    EXPECT_NE(load_error(path).find("/gp/alpha"), std::string::npos) << "alpha[21] = " << bad;
  }
  std::filesystem::remove(path);
}

// The same with y_train blown up: the reference α̂ = K⁻¹y then is the huge one.
TEST(ModelFile, HugeTrainingTargetIsRefused) {
  const std::string path = temp_path("y_huge.h5");
  const GaussianProcess gp = small_gp();
  save_model(path, gp);
  std::vector<double> y(gp.state().y_train.data(), gp.state().y_train.data() + gp.state().y_train.size());
  y[3] = 1e180;
  overwrite_doubles(path, "/gp/y_train", y);
  EXPECT_FALSE(load_error(path).empty());
  std::filesystem::remove(path);
}

TEST(ModelFile, CorruptLengthScaleIsDetectedThroughAlpha) {
  const std::string path = temp_path("length.h5");
  const GaussianProcess gp = small_gp();
  save_model(path, gp);
  const auto& l = gp.state().hyper.length_scales;
  overwrite_doubles(path, "/gp/length_scales", {l(0) * 1.01, l(1), l(2)});
  EXPECT_NE(load_error(path).find("inconsistent"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(ModelFile, NegativeLengthScaleIsNamed) {
  const std::string path = temp_path("neg.h5");
  save_model(path, small_gp());
  overwrite_doubles(path, "/gp/length_scales", {-1.0, 1.0, 1.0});
  EXPECT_NE(load_error(path).find("/gp/length_scales"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(ModelFile, IncompatibleSchemaVersionAndUnknownKindAreRefused) {
  const std::string path = temp_path("schema.h5");
  save_model(path, CoulombLaw(0.2));
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    long long version = 99;
    file.openAttribute("schema_version").write(H5::PredType::NATIVE_LLONG, &version);
  }
  EXPECT_NE(load_error(path).find("schema_version 99"), std::string::npos);
  save_model(path, CoulombLaw(0.2));
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    file.removeAttr("kind");
    H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
    file.createAttribute("kind", type, H5::DataSpace(H5S_SCALAR)).write(type, std::string("neural"));
  }
  EXPECT_NE(load_error(path).find("unknown model kind 'neural'"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(ModelFile, MissingDatasetIsNamed) {
  const std::string path = temp_path("missing.h5");
  save_model(path, small_gp(30));
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    file.unlink("/gp/y_train");
  }
  EXPECT_NE(load_error(path).find("/gp/y_train: missing"), std::string::npos);
  std::filesystem::remove(path);
}

// Regression: a flipped byte in a global-heap string length made the HDF5 library dereference
// wild pointers; `mufric serve` and `mufric describe` died of SIGSEGV. Parsed in a child process,
// the same file is an Error naming it, and the calling process lives on.
TEST(ModelFile, FileThatCrashesTheHdf5LibraryIsAnErrorNamingIt) {
  const std::string path = temp_path("heap.h5");
  save_model(path, small_gp(30));
  test::flip_global_heap_string_length(path);
  try {
    load_model_isolated(path);
    ADD_FAILURE() << "a corrupt file was loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(ModelFile, IsolatedLoadGivesTheSameModelAsALoad) {
  const std::string path = temp_path("isolated.h5");
  const GaussianProcess gp = small_gp(40);
  save_model(path, gp);
  const auto direct = load_model(path), isolated = load_model_isolated(path);
  const TrainingSet q = test::smooth_training_set(100, 5);
  const EvaluationRequest what{.std = true, .ci_level = 0.95, .gradient = true};
  const Evaluation a = direct->evaluate(q.x, what), b = isolated->evaluate(q.x, what);
  EXPECT_TRUE(bitwise_equal(a.mu, b.mu));
  EXPECT_TRUE(bitwise_equal(a.std, b.std));
  EXPECT_TRUE(bitwise_equal(a.gradient, b.gradient));
  // An ordinary validation failure in the child arrives with its own message.
  overwrite_doubles(path, "/gp/length_scales", {-1.0, 1.0, 1.0});
  try {
    load_model_isolated(path);
    ADD_FAILURE() << "a negative length scale was loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/gp/length_scales"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(ModelFile, KnownNoiseAndMicroScatterRoundTrip) {
  TrainingSet data = test::smooth_training_set(30, 5);
  data.mu_std = Eigen::VectorXd::Constant(data.mu.size(), 2e-3);
  GpTrainingOptions options;
  options.restarts = 0;
  options.sample_noise = true;
  const GaussianProcess gp = train_gaussian_process(data, options);
  const std::string path = temp_path("gp_noise.h5");
  save_model(path, gp);
  const auto loaded = load_model(path);
  const auto& b = dynamic_cast<const GaussianProcess&>(*loaded).state();
  EXPECT_TRUE(bitwise_equal(gp.state().known_noise, b.known_noise));
  EXPECT_EQ(gp.state().micro_std_error, b.micro_std_error);
  const TrainingSet q = test::smooth_training_set(50, 6);
  const EvaluationRequest what{.std = true, .ci_level = 0.95, .gradient = false};
  EXPECT_TRUE(bitwise_equal(gp.evaluate(q.x, what).std, loaded->evaluate(q.x, what).std));
  // A known-noise entry changed in the file no longer matches the stored factor: refused, named.
  std::vector<double> changed(b.known_noise.data(), b.known_noise.data() + b.known_noise.size());
  changed[3] *= 50.0;
  overwrite_doubles(path, "/gp/known_noise", changed);
  const std::string message = load_error(path);
  EXPECT_NE(message.find("/gp/"), std::string::npos) << message;
  std::filesystem::remove(path);
}

TEST(ModelFile, UriSchemes) {
  EXPECT_EQ(model_path_from_uri("file:///tmp/m.h5"), "/tmp/m.h5");
  EXPECT_EQ(model_path_from_uri("m.h5"), "m.h5");
  EXPECT_THROW(model_path_from_uri("s3://bucket/m.h5"), Error);
}

// A bare name that is not a file here is a shipped model's (MUFRIC_MODELS_DIR first); a path, a file
// here or a missing "*.h5" stays what it is; an unknown bare name is an error listing the shipped ones.
TEST(ModelFile, ABareNameIsAShippedModel) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("mufric_shipped_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "dry_default.h5") << "x";
  std::ofstream(dir / "wet.h5") << "x";
  ::setenv("MUFRIC_MODELS_DIR", dir.c_str(), 1);
  EXPECT_EQ(shipped_models_directory(), dir.string());
  EXPECT_EQ(shipped_model_names(), (std::vector<std::string>{"dry_default", "wet"}));
  const std::string shipped = (dir / "dry_default.h5").string();
  EXPECT_EQ(model_path_from_uri("dry_default"), shipped);
  EXPECT_EQ(model_path_from_uri("dry_default.h5"), shipped);
  EXPECT_EQ(model_path_from_uri("file://dry_default"), shipped);
  EXPECT_EQ(model_path_from_uri("elsewhere/dry_default"), "elsewhere/dry_default");
  EXPECT_EQ(model_path_from_uri("missing.h5"), "missing.h5");
  {
    // Regression: a folder or file named like a shipped model in the working directory shadowed it.
    const fs::path here = fs::current_path(), work = dir / "work";
    fs::create_directories(work / "dry_default");
    std::ofstream(work / "wet") << "x";
    std::ofstream(work / "mine") << "x";
    fs::current_path(work);
    EXPECT_EQ(model_path_from_uri("dry_default"), shipped);
    EXPECT_EQ(model_path_from_uri("wet"), (dir / "wet.h5").string());
    EXPECT_EQ(model_path_from_uri("./wet"), "./wet");  // the local one, asked for by path
    EXPECT_EQ(model_path_from_uri("mine"), "mine");    // no shipped model of that name
    fs::current_path(here);
  }
  try {
    model_path_from_uri("dry_defualt");
    ADD_FAILURE() << "an unknown name was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(": dry_default, wet)"), std::string::npos) << e.what();
  }
  ::unsetenv("MUFRIC_MODELS_DIR");
  fs::remove_all(dir);
}


GaussianProcess gp_with_fast_evaluator(unsigned data_seed) {
  GaussianProcess gp = test::fixed_hyper_gp(80, data_seed, 1.0, {0.5, 0.6, 0.7}, 1e-3);
  FastEvaluatorOptions f;
  f.check_points = 2000;
  gp.attach_fast_evaluator(std::make_shared<const FastEvaluator>(build_fast_evaluator(gp, f)));
  return gp;
}

// The fast evaluator is stored and read back as it was: same grid, same bounds, same answers.
TEST(ModelFile, FastEvaluatorRoundTrips) {
  const std::string path = temp_path("fast.h5");
  const GaussianProcess gp = gp_with_fast_evaluator(4);
  save_model(path, gp);
  const auto loaded = load_model(path);
  const auto* back = dynamic_cast<const GaussianProcess*>(loaded.get());
  ASSERT_NE(back, nullptr);
  ASSERT_NE(back->fast_evaluator(), nullptr);
  EXPECT_EQ(back->fast_evaluator()->grid().values(), gp.fast_evaluator()->grid().values());
  EXPECT_EQ(back->fast_evaluator()->bounds().mu_absolute, gp.fast_evaluator()->bounds().mu_absolute);
  EXPECT_EQ(back->fast_evaluator()->bounds().std_relative, gp.fast_evaluator()->bounds().std_relative);
  const Eigen::MatrixXd x = test::smooth_training_set(50, 8).x;
  const Evaluation a = gp.evaluate(x, {.std = true}), b = back->evaluate(x, {.std = true});
  EXPECT_EQ(a.fast_points, 50);
  EXPECT_EQ(b.fast_points, 50);
  for (Eigen::Index i = 0; i < 50; ++i) EXPECT_EQ(a.mu(i), b.mu(i));
  std::filesystem::remove(path);
}

// One changed node value, or a looser stored bound, breaks the checksum; a grid of another model
// (a valid checksum) fails the spot check against the exact model. Each is refused naming the group.
TEST(ModelFile, ATamperedOrForeignFastEvaluatorIsRefused) {
  const std::string path = temp_path("fast_bad.h5");
  const GaussianProcess gp = gp_with_fast_evaluator(4);
  save_model(path, gp);
  std::vector<double> values = gp.fast_evaluator()->grid().values();
  values[values.size() / 2] += 1e-6;
  overwrite_doubles(path, "/gp/fast_evaluator/values", values);
  EXPECT_NE(load_error(path).find("/gp/fast_evaluator: checksum mismatch"), std::string::npos) << load_error(path);

  save_model(path, gp);
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    const double looser = 1.0;
    file.openGroup("/gp/fast_evaluator").openAttribute("bound_mu_absolute").write(H5::PredType::NATIVE_DOUBLE, &looser);
  }
  EXPECT_NE(load_error(path).find("checksum mismatch"), std::string::npos) << load_error(path);

  GaussianProcess other = gp_with_fast_evaluator(5);  // other data, same box
  GaussianProcess mixed = gp;
  mixed.attach_fast_evaluator(std::make_shared<const FastEvaluator>(*other.fast_evaluator()));
  save_model(path, mixed);
  EXPECT_NE(load_error(path).find("is not the model's value there"), std::string::npos) << load_error(path);
  std::filesystem::remove(path);
}

// A model `train` would write for noise-free data (σ at the noise floor, where two evaluation paths
// round σ differently far beyond 1e-9) loads with its fast evaluator: the load-time check holds a node
// to the file's certified bound, not to a tolerance the quantity cannot meet (issue 30).
TEST(ModelFile, ANoiseFreeModelLoadsWithItsFastEvaluator) {
  const std::string path = temp_path("noise_floor.h5");
  GaussianProcess gp = test::fixed_hyper_gp(400, 13, 50.0, {1.5, 2.0, 3.0}, 1e-6);
  gp.attach_fast_evaluator(std::make_shared<const FastEvaluator>(build_fast_evaluator(gp, FastEvaluatorOptions{})));
  save_model(path, gp);
  const auto loaded = load_model(path);
  const auto* back = dynamic_cast<const GaussianProcess*>(loaded.get());
  ASSERT_NE(back, nullptr);
  ASSERT_NE(back->fast_evaluator(), nullptr);
  EXPECT_EQ(back->fast_evaluator()->bounds().std_floor, gp.fast_evaluator()->bounds().std_floor);
  EXPECT_EQ(back->evaluate(test::smooth_training_set(20, 8).x, {.std = true}).fast_points, 20);
  std::filesystem::remove(path);
}

// A schema-2 file (before fast evaluators) still loads, with none: the exact model answers.
TEST(ModelFile, AnOlderSchemaLoadsWithoutAFastEvaluator) {
  const std::string path = temp_path("schema2.h5");
  GaussianProcess gp = gp_with_fast_evaluator(4);
  gp.attach_fast_evaluator(nullptr);
  save_model(path, gp);
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    const long long version = 2;
    file.openAttribute("schema_version").write(H5::PredType::NATIVE_LLONG, &version);
  }
  const auto loaded = load_model(path);
  EXPECT_EQ(dynamic_cast<const GaussianProcess&>(*loaded).fast_evaluator(), nullptr);
  EXPECT_EQ(loaded->evaluate(test::smooth_training_set(10, 8).x, {}).fast_points, 0);
  std::filesystem::remove(path);
}


// The campaign behind a model's data travels with its file and `describe` shows it; a file from
// before it was kept loads with none.
TEST(ModelFile, TheDatasetDescriptionRoundTripsAndAnOlderFileHasNone) {
  TrainingSet data = test::smooth_training_set(40, 2);
  data.description = "micro-model plan (a test scene); plan 40 points, design sobol (seed 3)";
  GpTrainingOptions options;
  options.restarts = 0;
  const GaussianProcess gp = train_gaussian_process(data, options);
  EXPECT_EQ(gp.state().summary.dataset_description, data.description);
  const std::string path = temp_path("described.h5");
  save_model(path, gp);
  const auto loaded = load_model(path);
  EXPECT_EQ(dynamic_cast<const GaussianProcess&>(*loaded).state().summary.dataset_description, data.description);
  EXPECT_NE(loaded->summary().find("trained on: " + data.description), std::string::npos) << loaded->summary();
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    file.openGroup("/gp/training").removeAttr("dataset_description");
  }
  const auto older = load_model(path);
  EXPECT_EQ(dynamic_cast<const GaussianProcess&>(*older).state().summary.dataset_description, "");
  EXPECT_EQ(older->summary().find("trained on:"), std::string::npos);
  std::filesystem::remove(path);
}

// A model's extrapolation policy and μ range travel with its file; a bad one is refused by name.
TEST(ModelFile, ExtrapolationPolicyAndMuRangeRoundTrip) {
  const std::string path = temp_path("policy.h5");
  CoulombLaw law(0.3);
  law.set_default_extrapolation(Extrapolation::refuse);
  law.set_mu_range(0.05, 0.8);
  save_model(path, law);
  const auto back = load_model(path);
  EXPECT_EQ(back->default_extrapolation(), Extrapolation::refuse);
  EXPECT_EQ(back->mu_min(), 0.05);
  EXPECT_EQ(back->mu_max(), 0.8);
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    file.removeAttr("extrapolation");
    H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
    file.createAttribute("extrapolation", type, H5::DataSpace(H5S_SCALAR)).write(type, std::string("nearest"));
  }
  EXPECT_NE(load_error(path).find("attribute extrapolation"), std::string::npos) << load_error(path);
  save_model(path, law);
  {
    H5::H5File file(path, H5F_ACC_RDWR);
    const double inverted = -1.0;
    file.openAttribute("mu_max").write(H5::PredType::NATIVE_DOUBLE, &inverted);
  }
  EXPECT_NE(load_error(path).find("mu_min, mu_max"), std::string::npos) << load_error(path);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace mufric
