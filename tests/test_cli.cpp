// The mufric executable end to end: bad input ends with a one-line error naming the field, file or
// row and a non-zero exit code; the happy path writes and reads real files.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <csignal>
#include <thread>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <cmath>
#include <string>
#include <algorithm>
#include <regex>
#include <sstream>
#include <vector>

#include <sched.h>

#include <nlohmann/json.hpp>

#include "corrupt_files.hpp"

namespace {

struct CommandResult {
  int exit_code;
  std::string output;  // stdout and stderr
};

// A shell command's exit code and output (give it 2>&1 for stderr too).
CommandResult run_shell(const std::string& command) {
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

// `launcher` goes before the executable: "timeout 20", "taskset -c 0 env OMP_NUM_THREADS=1", ….
CommandResult run(const std::string& arguments, const std::string& launcher = "") {
  return run_shell(launcher + " " + std::string(MUFRIC_EXE) + " " + arguments + " 2>&1");
}

size_t line_count(const std::string& text) { return static_cast<size_t>(std::count(text.begin(), text.end(), '\n')); }

// The first CPU this process may run on (`taskset -c 0` would fail where CPU 0 is not among them).
int first_allowed_cpu() {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof mask, &mask) == 0) {
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
      if (CPU_ISSET(cpu, &mask)) return cpu;
    }
  }
  return 0;
}

std::string read_text(const std::string& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("mufric_cli_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::filesystem::path dir_;
};

// `mufric serve --models DIR` (DIR "": no --models) in a child process on a free loopback port, its stderr in LOG;
// `launcher` goes before the executable ({"taskset", "-c", "0"}).
class ServeProcess {
 public:
  ServeProcess(const std::string& models, const std::string& log, const std::string& ready_file,
               const std::vector<std::string>& launcher = {}) {
    pid_ = fork();
    if (pid_ == 0) {
      freopen(log.c_str(), "w", stderr);
      unsetenv("GOMP_SPINCOUNT");  // as a user who chose no wait policy
      unsetenv("OMP_WAIT_POLICY");
      std::vector<std::string> words = launcher;
      words.insert(words.end(), {MUFRIC_EXE, "serve", "--listen", "127.0.0.1:0", "--ready-file", ready_file});
      if (!models.empty()) words.insert(words.end(), {"--models", models});  // none: the shipped models
      std::vector<char*> argv;
      for (std::string& word : words) argv.push_back(word.data());
      argv.push_back(nullptr);
      execvp(argv[0], argv.data());
      _exit(127);
    }
    for (int i = 0; i < 100 && address_.empty() && pid_ > 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::ifstream(ready_file) >> address_;
    }
  }
  ~ServeProcess() {
    if (pid_ > 0) stop();
  }
  pid_t pid() const { return pid_; }
  const std::string& address() const { return address_; }  // empty: it did not start
  // SIGTERM, then the exit status (−1 unless it exited normally).
  int stop() {
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  std::string address_;
};

TEST_F(Cli, HelpExplainsTheSubcommands) {
  const CommandResult r = run("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* word : {"train", "eval", "predict", "law", "dataset", "bench", "800MPa"}) {
    EXPECT_NE(r.output.find(word), std::string::npos) << word;
  }
  EXPECT_EQ(run("train --help").exit_code, 0);
}

// Regression (issue 30): a command line CLI11 refused ended with CLI11's own exit code (105, 106,
// 114, …) and two lines without mufric's prefix; the README promises one line and exit code 2 for
// every error. --help and --version keep exit code 0 and their output.
TEST_F(Cli, CommandLineErrorsAreOneLineWithExitCode2) {
  for (const std::string& command : std::vector<std::string>{
           "micro run /nonexistent.json", "law coulomb --mu -1 --out " + path("c.h5"),
           "dataset plan --samples 0 --out " + path("p.h5"), "law coulomb --no-such-flag", "no-such-command"}) {
    const CommandResult r = run(command);
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.output;
    EXPECT_EQ(r.output.rfind("mufric: error: ", 0), 0u) << command << ": " << r.output;
    EXPECT_EQ(line_count(r.output), 1u) << command << ": " << r.output;
  }
  EXPECT_NE(run("micro run /nonexistent.json").output.find("/nonexistent.json"), std::string::npos);
  EXPECT_NE(run("dataset plan --samples 0").output.find("mufric dataset plan --help"), std::string::npos);
  // A CSV with a header and no rows says so (regression: "an input was not given").
  { std::ofstream(path("header-only.csv")) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C]\n"; }
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("c.h5")).exit_code, 0);
  EXPECT_EQ(run("predict --model " + path("c.h5") + " --csv " + path("header-only.csv")).output,
            "mufric: error: " + path("header-only.csv") + ": a header and no rows: no point to predict\n");
  // A mistyped subcommand gets the nearest name, at any level; a word far from every name gets none.
  EXPECT_NE(run("predcit --model dry_default").output.find("did you mean `predict`?"), std::string::npos)
      << run("predcit --model dry_default").output;
  EXPECT_NE(run("dataset paln").output.find("did you mean `plan`?"), std::string::npos) << run("dataset paln").output;
  EXPECT_EQ(run("no-such-command").output.find("did you mean"), std::string::npos);
  for (const std::string command : {"--help", "--version", "dataset plan --help"}) {
    const CommandResult r = run(command);
    EXPECT_EQ(r.exit_code, 0) << command << ": " << r.output;
    EXPECT_EQ(r.output.find("error"), std::string::npos) << command << ": " << r.output;
  }
}

// Regression: `mufric describe` on a model file with a flipped global-heap string length died of
// SIGSEGV inside the HDF5 library. Now a one-line error naming the file, exit code 2.
TEST_F(Cli, FileThatCrashesTheHdf5LibraryIsAOneLineError) {
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("c.h5")).exit_code, 0);
  mufric::test::flip_global_heap_string_length(path("c.h5"));
  for (const std::string& command : {"describe " + path("c.h5"), "predict --model " + path("c.h5") + " --p 1MPa --v 1m/s --T 20C"}) {
    const CommandResult r = run(command);
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.output;
    EXPECT_NE(r.output.find(path("c.h5")), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  }
}

TEST_F(Cli, LawPredictTrainEvalChain) {
  ASSERT_EQ(run("law seward --table 4 --out " + path("law.h5")).exit_code, 0);
  CommandResult r = run("predict --model " + path("law.h5") + " --p 80MPa --v 10m/min --angle 90deg");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Table 4, 90°: 0.149911 + 0.013133·10 − 0.000753·80 = 0.221001
  EXPECT_NE(r.output.find("mu = 0.221001"), std::string::npos) << r.output;
  ASSERT_EQ(run("dataset from-model --model " + path("law.h5") + " --samples 120 --out " + path("db.h5")).exit_code, 0);
  ASSERT_EQ(run("dataset from-model --model " + path("law.h5") + " --samples 50 --seed 5 --out " + path("t.h5")).exit_code, 0);
  r = run("train --data " + path("db.h5") + " --out " + path("gp.h5") + " --restarts 1");  // a work budget: the same grid under a sanitizer
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("log marginal likelihood"), std::string::npos);
  EXPECT_NE(r.output.find("leave-one-out"), std::string::npos);
  EXPECT_NE(r.output.find("start 1"), std::string::npos);
  r = run("eval --model file://" + path("gp.h5") + " --test " + path("t.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("95 % interval coverage"), std::string::npos);
  r = run("predict --model " + path("gp.h5") + " --p 80MPa --v 10m/min --angle 90deg");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("95 % interval ["), std::string::npos);
  EXPECT_NE(r.output.find("(fast evaluator)"), std::string::npos) << r.output;  // train builds it
}

// Regression: when even the coarsest grid exceeded --fast-max-mb, train exited 2 and wrote no model.
TEST_F(Cli, TrainWritesTheExactModelWhenNoGridFitsTheCap) {
  ASSERT_EQ(run("law seward --table 4 --out " + path("law.h5")).exit_code, 0);
  ASSERT_EQ(run("dataset from-model --model " + path("law.h5") + " --samples 30 --out " + path("db.h5")).exit_code, 0);
  const CommandResult r = run("train --data " + path("db.h5") + " --out " + path("gp.h5") + " --restarts 0 --fast-max-mb 0.001");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fast evaluator (model): not stored: the coarsest grid needs"), std::string::npos) << r.output;
  // The last line says so (issue 63: a user read only that line and took the exact GP for the fast one).
  EXPECT_NE(r.output.find("; no fast evaluator: the exact GP answers every request"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(path("gp.h5")));
  EXPECT_NE(run("describe " + path("gp.h5")).output.find("fast evaluator: none"), std::string::npos);
}

// A model trained without a fast evaluator gets one from `upgrade`; describe and predict say so.
TEST_F(Cli, UpgradeAddsAFastEvaluator) {
  ASSERT_EQ(run("law seward --table 4 --out " + path("law.h5")).exit_code, 0);
  ASSERT_EQ(run("dataset from-model --model " + path("law.h5") + " --samples 80 --out " + path("db.h5")).exit_code, 0);
  ASSERT_EQ(run("train --data " + path("db.h5") + " --out " + path("gp.h5") + " --restarts 0 --no-fast-evaluator").exit_code, 0);
  CommandResult r = run("describe " + path("gp.h5"));
  EXPECT_NE(r.output.find("fast evaluator: none"), std::string::npos) << r.output;
  r = run("predict --model " + path("gp.h5") + " --p 80MPa --v 10m/min --angle 90deg");
  EXPECT_NE(r.output.find("(exact model)"), std::string::npos) << r.output;
  r = run("upgrade " + path("gp.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("meets the tolerances"), std::string::npos) << r.output;
  r = run("describe " + path("gp.h5"));
  EXPECT_NE(r.output.find("measured bound: mu"), std::string::npos) << r.output;
  r = run("predict --model " + path("gp.h5") + " --p 80MPa --v 10m/min --angle 90deg");
  EXPECT_NE(r.output.find("(fast evaluator)"), std::string::npos) << r.output;
  EXPECT_NE(run("upgrade " + path("nope.h5")).exit_code, 0);
}

// Regression (issue 30): a model `train` wrote for noise-free data (the learned noise at its lower
// bound, σ a cancelling difference) was refused by `describe`, and its fast evaluator refined for
// minutes. It must load, with its grid built within the default budget.
TEST_F(Cli, AModelTrainedOnNoiseFreeDataLoadsInEveryCommand) {
  {
    std::ofstream csv(path("smooth.csv"));
    csv << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n";
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    csv.precision(17);
    for (int i = 0; i < 400; ++i) {
      const double a = u(rng), b = u(rng), c = u(rng);
      csv << 300 + 1000 * a << "," << 22.5 + 177.5 * b << "," << 25 + 875 * c << ","
          << 0.2 + 0.03 * std::sin(2 * a) * std::cos(1.5 * b) - 0.04 * c * c << "\n";
    }
  }
  CommandResult r = run("train --data " + path("smooth.csv") + " --out " + path("gp.h5") + " --restarts 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("noise variance is at its lower bound"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("meets the tolerances"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("; its fast evaluator answers default requests"), std::string::npos) << r.output;
  r = run("describe " + path("gp.h5"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("measured bound: mu"), std::string::npos) << r.output;
  r = run("predict --model " + path("gp.h5") + " --p 800MPa --v 100m/min --T 500C");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(fast evaluator)"), std::string::npos) << r.output;
}

// Data that cannot be a model's are refused before anything runs, naming the file, line or column
// (issue 30): an extra column, a misspelt input, a μ outside the μ range, a range excluding the
// data, a plan below absolute zero.
TEST_F(Cli, DataThatCannotBeAModelsDataIsRefusedByName) {
  std::ofstream(path("extra.csv")) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],run_id,mu\n"
                                      "800,100,500,1,0.2\n900,120,400,2,0.25\n";
  CommandResult r = run("train --data " + path("extra.csv") + " --out " + path("m.h5"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("column 'run_id' is not a model input"), std::string::npos) << r.output;
  std::ofstream(path("big.csv")) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n"
                                    "800,100,500,0.2\n900,120,400,5.0\n";
  r = run("train --data " + path("big.csv") + " --out " + path("m.h5"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("big.csv: converged sample 2, column mu: 5 is outside the model's mu range [0, 1]"),
            std::string::npos) << r.output;
  std::ofstream(path("ok.csv")) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n"
                                   "800,100,500,0.2\n900,120,400,0.25\n";
  r = run("train --data " + path("ok.csv") + " --out " + path("m.h5") + " --mu-range 0.3 0.4");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("given by --mu-range"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(path("m.h5")));
  r = run("train --data " + path("ok.csv") + " --out " + path("m.h5") + " --fast-max-work inf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--fast-max-work: Value inf is not a finite number"), std::string::npos) << r.output;
  r = run("dataset plan --out " + path("p.h5") + " --samples 4 --T -400C:25C");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--T '-400C:25C': -400°C is below absolute zero"), std::string::npos) << r.output;
  r = run("dataset plan --out " + path("p.h5") + " --samples 4 --p -500MPa:-100MPa");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("-500MPa is below 0MPa"), std::string::npos) << r.output;
}

// A point without an answer says which input and why, and predict exits 2; --csv answers many points
// as a CSV with a status and reason per row (issue 30 items 4 and the small ones).
TEST_F(Cli, PredictSaysWhyAPointHasNoAnswerAndAnswersACsv) {
  ASSERT_EQ(run("law seward --table 4 --out " + path("law.h5")).exit_code, 0);
  CommandResult r = run("predict --model " + path("law.h5") + " --p 10000MPa --v 10m/min --angle 90deg --extrapolation refuse");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("mufric: error: OUT_OF_BOX: contact_pressure: 1e+04MPa is above the box"), std::string::npos)
      << r.output;
  r = run("predict --model " + path("law.h5") + " --p -5MPa --v 10m/min --angle 90deg");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("INVALID_INPUT: contact_pressure: -5MPa is below 0MPa"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("mu = "), std::string::npos) << "a point without an answer printed a mu block:\n" << r.output;
  EXPECT_EQ(r.output.find("nan"), std::string::npos) << r.output;
  r = run("predict --model " + path("law.h5") + " --p 10000MPa --v 10m/min --angle 270deg");
  EXPECT_EQ(r.exit_code, 0) << r.output;  // clamped: answered, and says why it is EXTRAPOLATED and how it was answered
  EXPECT_NE(r.output.find("outside the training box: contact_pressure"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("answered at contact_pressure = "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("policy clamp"), std::string::npos) << r.output;
  r = run("predict --model " + path("law.h5") + " --p 10000MPa --v 10m/min --angle 270deg --extrapolation raw");
  EXPECT_NE(r.output.find("policy raw"), std::string::npos) << r.output;
  r = run("predict --model " + path("law.h5") + " --p 80MPa --v 10m/min --angle 270deg");
  EXPECT_NE(r.output.find("status OK"), std::string::npos) << r.output;  // 270° is 90°: inside
  std::ofstream(path("points.csv")) << "contact_pressure[MPa],sliding_velocity[m/min],fibre_angle[deg]\n"
                                       "80,10,90\n-5,10,90\n";
  r = run("predict --model " + path("law.h5") + " --csv " + path("points.csv") + " --out " + path("answers.csv"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("points.csv: line 3: INVALID_INPUT"), std::string::npos) << r.output;
  const std::string answers = read_text(path("answers.csv"));
  EXPECT_NE(answers.find("mu,std,lo,hi,status,reason"), std::string::npos) << answers;
  EXPECT_NE(answers.find("80,10,90,0.221001"), std::string::npos) << answers;  // Table 4 at 90°, as above
  EXPECT_NE(answers.find("INVALID_INPUT,\"contact_pressure: -5MPa"), std::string::npos) << answers;
}

// Two answer CSVs of `predict` agree: the same rows and text fields, every number within
// `relative` of the other's.
void expect_same_answers(const std::string& expected, const std::string& actual, double relative) {
  const auto rows = [](const std::string& text) {
    std::vector<std::vector<std::string>> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
      std::vector<std::string> fields;
      bool quoted = false;
      std::string field;
      for (const char c : line) {
        if (c == '"') quoted = !quoted;
        if (c == ',' && !quoted) {
          fields.push_back(field);
          field.clear();
        } else {
          field += c;
        }
      }
      fields.push_back(field);
      out.push_back(fields);
    }
    return out;
  };
  const auto a = rows(expected), b = rows(actual);
  ASSERT_EQ(a.size(), b.size()) << actual;
  for (size_t r = 0; r < a.size(); ++r) {
    ASSERT_EQ(a[r].size(), b[r].size()) << "row " << r;
    for (size_t f = 0; f < a[r].size(); ++f) {
      char* end_a = nullptr;
      char* end_b = nullptr;
      const double x = std::strtod(a[r][f].c_str(), &end_a), y = std::strtod(b[r][f].c_str(), &end_b);
      const bool numbers = !a[r][f].empty() && *end_a == '\0' && !b[r][f].empty() && *end_b == '\0';
      if (numbers) {
        EXPECT_NEAR(y, x, relative * std::abs(x)) << "row " << r << ", field " << f;
      } else {
        EXPECT_EQ(b[r][f], a[r][f]) << "row " << r << ", field " << f;
      }
    }
  }
}

// The shipped model (models/dry_default.h5) is what `train` makes of the committed campaign database
// with its defaults (campaigns/dry_default/train.sh): retrained, it gives the same answers, interval and
// patch scatter, inside and outside the box. A bare name finds it in every command; a wrong one is
// named with the shipped models. "The same" to 1e-5: the fit's optimiser runs through vectorised
// kernels whose rounding differs between machines (a refit on an AVX2 AMD EPYC differs from the model
// trained on an AVX-512 Xeon by at most 1.3e-7 relative); retrained from other data or with other
// defaults the answers move by percents.
TEST_F(Cli, TheShippedModelIsTheCampaignsFit) {
  ::setenv("MUFRIC_MODELS_DIR", MUFRIC_SOURCE_DIR "/models", 1);
  // Without a fast evaluator, as models/ keeps it (campaigns/dry_default/train.sh): exact against exact.
  CommandResult r = run(std::string("train --data ") + MUFRIC_SOURCE_DIR "/campaigns/dry_default/db.h5 --out " +
                        path("refit.h5") + " --no-fast-evaluator");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ofstream points(path("q.csv"));
  points << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C]\n";
  for (int i = 0; i < 40; ++i) {  // a lattice over the box and beyond it on every side
    points << 100 + 90 * i << "," << 0.5 + 55 * i << "," << 10 + 25 * (i % 40) << "\n";
  }
  points.close();
  r = run("predict --model dry_default --csv " + path("q.csv") + " --out " + path("shipped.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run("predict --model " + path("refit.h5") + " --csv " + path("q.csv") + " --out " + path("refit.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string shipped = read_text(path("shipped.csv"));
  EXPECT_NE(shipped.find("patch_std"), std::string::npos) << shipped;
  expect_same_answers(shipped, read_text(path("refit.csv")), 1e-5);
  r = run("describe dry_default");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("averaged over all draws"), std::string::npos) << r.output;
  {  // `serve` without --models serves it
    ServeProcess server("", path("serve.log"), path("ready"));
    ASSERT_FALSE(server.address().empty()) << read_text(path("serve.log"));
    r = run("predict --model grpc://" + server.address() + "/dry_default --p 800MPa --v 100m/min --T 500C");
    const CommandResult local = run("predict --model dry_default --p 800MPa --v 100m/min --T 500C");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output, local.output);
    EXPECT_NE(read_text(path("serve.log")).find("serving the shipped models in"), std::string::npos);
  }
  r = run("describe dry_defualt");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no shipped model of that name"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(": dry_default, ti6al4v_tin)"), std::string::npos) << r.output;
  ::unsetenv("MUFRIC_MODELS_DIR");
}

// The shipped Ti6Al4V model (models/ti6al4v_tin.h5) is what campaigns/ti6al4v_tin/train.sh makes of
// the committed campaign database and the measured cuts: rerun, the calibration gives the same
// answers at the six cutting speeds' rake-face states and at the box's corners. Its build copy carries
// a fast evaluator that meets the tolerances (a fresh install's fast path: CMakeLists.txt's per-model
// grid budget). "The same" to 1e-5 relative on this machine, where the ensemble sampler's seeded
// chains repeat bit for bit; on another vector width a refit GP's rounding may move a walker's
// accept-reject decision, and the posterior mean then differs by its Monte Carlo error (about 1e-3).
TEST_F(Cli, TheShippedTi6Al4VModelIsTheCalibration) {
  if (MUFRIC_EXE_SANITIZED) GTEST_SKIP() << "a 12 000-step ensemble calibration: release build only";
  const CommandResult trained = run_shell(std::string("MUFRIC=") + MUFRIC_EXE + " OUT=" + path("ti.h5") + " bash " +
                                          MUFRIC_SOURCE_DIR "/campaigns/ti6al4v_tin/train.sh 2>&1");
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  std::ofstream points(path("q.csv"));
  points << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C]\n"
         << "915.6,2.64,420.3\n1006.9,4.49,497.4\n901.1,5.57,504.9\n972.5,14.05,842.1\n1319.0,23.90,831.5\n"
         << "1289.2,31.21,844.5\n300,1,100\n2000,60,1100\n300,60,1100\n2000,1,100\n";
  points.close();
  CommandResult r = run(std::string("predict --model ") + MUFRIC_SOURCE_DIR "/models/ti6al4v_tin.h5 --csv " + path("q.csv") +
                        " --out " + path("shipped.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run("predict --model " + path("ti.h5") + " --csv " + path("q.csv") + " --out " + path("rerun.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  expect_same_answers(read_text(path("shipped.csv")), read_text(path("rerun.csv")), 1e-5);
  r = run("describe ti6al4v_tin");  // the build's copy, by its bare name
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fast evaluator: grid"), std::string::npos) << r.output;  // stored only when it meets them
  // It names the repository's data file and its hash, and the conditions' posterior in MPa and °C.
  const std::string data_file = "data/cirp2022_ti6al4v_tin/rake_face_mu_calibration.csv";
  const std::string hash = run_shell(std::string("sha256sum ") + MUFRIC_SOURCE_DIR "/" + data_file).output.substr(0, 64);
  EXPECT_NE(r.output.find("measurements: " + data_file + " (sha256 " + hash + "): Rake-face friction"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("derived by; data/"), std::string::npos) << "a line break shown as '; '";
  EXPECT_TRUE(std::regex_search(r.output, std::regex("posterior contact_pressure \\(rake_face_mu_calibration.csv line 12\\): "
                                                     "mean [0-9.]+MPa, sd [0-9.]+MPa, 95 % [0-9.]+MPa \\.\\. [0-9.]+MPa")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("posterior temperature \\(rake_face_mu_calibration.csv line 12\\): mean [0-9.]+°C, sd [0-9.]+ K")))
      << r.output;
  // The file keeps the priors a recalibration needs: an on-line learner takes it with its campaign.
  std::filesystem::create_directories(path("served"));
  std::filesystem::copy_file(MUFRIC_SOURCE_DIR "/models/ti6al4v_tin.h5", path("served/ti.h5"));
  std::filesystem::copy_file(MUFRIC_SOURCE_DIR "/campaigns/ti6al4v_tin/db.h5", path("db.h5"));
  r = run("learn init " + path("learner") + " --db " + path("db.h5") + " --model " + path("served/ti.h5") + " --log " + path("ti.csv"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("serving version"), std::string::npos) << r.output;
}

TEST_F(Cli, NumberWithoutUnitNamesTheFlag) {
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("c.h5")).exit_code, 0);
  const CommandResult r = run("predict --model " + path("c.h5") + " --p 800 --v 100m/min --T 500C");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--p: '800' has no unit"), std::string::npos) << r.output;
}

TEST_F(Cli, UnknownUnitAndMissingInputAreNamed) {
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("c.h5")).exit_code, 0);
  CommandResult r = run("predict --model " + path("c.h5") + " --p 800MPa --v 100furlong/min --T 500C");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--v"), std::string::npos);
  EXPECT_NE(r.output.find("unknown unit"), std::string::npos);
  r = run("predict --model " + path("c.h5") + " --p 800MPa --v 100m/min");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--T is required"), std::string::npos) << r.output;
}

TEST_F(Cli, MissingFileIsNamed) {
  const CommandResult r = run("train --data " + path("nope.h5") + " --out " + path("m.h5"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("nope.h5': no such file"), std::string::npos) << r.output;
}

TEST_F(Cli, NaNInATrainingRowIsNamedByLine) {
  std::ofstream(path("d.csv")) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n"
                                  "800,100,500,0.3\n900,120,nan,0.31\n";
  const CommandResult r = run("train --data " + path("d.csv") + " --out " + path("m.h5"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("line 3, column 'temperature'"), std::string::npos) << r.output;
  // One line: the error is the whole message.
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST_F(Cli, ServeAnswersPredictOverGrpcAndDrainsOnSigterm) {
  std::filesystem::create_directories(path("models"));
  ASSERT_EQ(run("law seward --table 4 --out " + path("models/law.h5")).exit_code, 0);
  ServeProcess server(path("models"), path("serve.log"), path("address"));
  const std::string& address = server.address();
  const pid_t pid = server.pid();
  ASSERT_FALSE(address.empty()) << "server did not start";
  {
    // Regression: with libgomp's default spinning, a micro run beside one CPU-bound process took
    // 8–15× its one-core time. mufric restarts itself with a bounded spin count unless the user set
    // a wait policy; the running server's environment shows it.
    std::ifstream environ_file("/proc/" + std::to_string(pid) + "/environ");
    std::stringstream environ_text;
    environ_text << environ_file.rdbuf();
    EXPECT_NE(environ_text.str().find(std::string("GOMP_SPINCOUNT=5000") + '\0'), std::string::npos);
  }
  const CommandResult r = run("predict --model grpc://" + address + "/law --p 80MPa --v 10m/min --angle 90deg");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("mu = 0.221001"), std::string::npos) << r.output;
  const CommandResult described = run("describe grpc://" + address + "/law");
  EXPECT_EQ(described.exit_code, 0) << described.output;
  EXPECT_NE(described.output.find("kind mlr"), std::string::npos) << described.output;
  EXPECT_NE(described.output.find("contact_pressure"), std::string::npos) << described.output;
  const CommandResult missing = run("predict --model grpc://" + address + "/other --p 80MPa --v 10m/min --angle 90deg");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("NOT_FOUND"), std::string::npos) << missing.output;
  EXPECT_EQ(server.stop(), 0);
  std::ifstream log(path("serve.log"));
  std::string text, line;
  while (std::getline(log, line)) text += line + "\n";
  EXPECT_NE(text.find("SIGTERM: draining"), std::string::npos) << text;
}

// Regression (issue 30): gRPC sets SO_REUSEPORT, so a second server on a port where one already
// listened started too, and the kernel handed each connection to one of the two at random. Now the
// second is refused naming the port; so is an address that is no host:port, before gRPC logs a line.
// Regression: `serve` on a folder with no model, and a bearer token over plaintext on a
// non-loopback address, started without a word.
TEST_F(Cli, ServeWarnsOfAnEmptyFolderAndOfATokenInTheClear) {
  std::filesystem::create_directories(path("empty"));
  { std::ofstream(path("token")) << "s3cret\n"; }
  const CommandResult r = run("serve --models " + path("empty") + " --listen 0.0.0.0:0 --token-file " + path("token"),
                              "timeout -s INT 4");
  EXPECT_NE(r.output.find("no model in " + path("empty") + " yet"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--token-file over plaintext on 0.0.0.0:0"), std::string::npos) << r.output;
  const CommandResult loopback = run("serve --models " + path("empty") + " --listen 127.0.0.1:0 --token-file " +
                                     path("token"), "timeout -s INT 4");
  EXPECT_EQ(loopback.output.find("over plaintext"), std::string::npos) << loopback.output;
}

TEST_F(Cli, ServeRefusesAPortInUseAndAnAddressThatIsNoHostAndPort) {
  std::filesystem::create_directories(path("models"));
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("models/law.h5")).exit_code, 0);
  ServeProcess first(path("models"), path("serve.log"), path("address"));
  ASSERT_FALSE(first.address().empty()) << "server did not start";
  // Without the fix the second server serves until killed: `timeout` makes that a failure, not a hang.
  const std::string serve = "serve --models " + path("models") + " --listen ";
  CommandResult r = run(serve + first.address(), "timeout 20");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(r.output, "mufric: error: --listen " + first.address() + ": the port is in use (another server listens there?)\n");
  for (const std::string listen : {"127.0.0.1:99999", "127.0.0.1:65536", "nonsense", "127.0.0.1:", "127.0.0.1:x"}) {
    r = run(serve + listen, "timeout 20");
    EXPECT_EQ(r.exit_code, 2) << listen << ": " << r.output;
    EXPECT_EQ(r.output.rfind("mufric: error: --listen " + listen + ": ", 0), 0u) << r.output;  // nothing from gRPC first
    EXPECT_EQ(line_count(r.output), 1u) << r.output;
  }
  // A memory cap that leaves calls in flight too little is refused at start, naming the option.
  r = run(serve + "127.0.0.1:0 --max-memory-mb 40", "timeout 20");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("mufric: error: --max-memory-mb 40: the models take "), std::string::npos) << r.output;
  r = run(serve + "55060", "timeout 20");  // a port alone: say how to write it, not "no port"
  EXPECT_EQ(r.output, "mufric: error: --listen 55060: a port alone; give host:port, e.g. 127.0.0.1:55060 (loopback) "
                      "or 0.0.0.0:55060 (every interface)\n");
  // A directory given as a model is named as one.
  r = run("predict --model " + path("models") + " --p 80MPa --v 10m/min --T 20C");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(path("models") + "': a directory, not a file"), std::string::npos) << r.output;
  // The first server still answers.
  r = run("predict --model grpc://" + first.address() + "/law --p 80MPa --v 10m/min --T 20C");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(first.stop(), 0);
}

// Regression (issue 30): `mufric bench` with failed calls exited 0, so a script took a table of
// errors for a measurement. The server stops while the bench runs; the calls after that fail (no
// retries), the table is still printed and the exit code is 2 with the count and the first error.
TEST_F(Cli, BenchWithFailedCallsExits2) {
  std::filesystem::create_directories(path("models"));
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("models/law.h5")).exit_code, 0);
  ServeProcess server(path("models"), path("serve.log"), path("address"));
  ASSERT_FALSE(server.address().empty()) << "server did not start";
  std::thread stop_midway([&server] {
    std::this_thread::sleep_for(std::chrono::seconds(2));
    server.stop();
  });
  const CommandResult r =
      run("bench --model grpc://" + server.address() + "/law --batch 1 --seconds 4 --client-options retries=0");
  stop_midway.join();
  EXPECT_EQ(r.exit_code, 2) << r.output;
  const size_t error = r.output.find("mufric: error: bench: ");
  ASSERT_NE(error, std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" calls failed, the first: Evaluate on model 'law' failed (", error),
            std::string::npos) << r.output;
  EXPECT_NE(r.output.find("points/s"), std::string::npos) << r.output;  // the table, before the error
}

// Regression (issue 30): `serve --drain -5` was accepted, and NaN passed every CLI::Range (each
// comparison with it is false): `--poll nan` reached the server loop. Each is refused naming the
// option, before a server starts (`timeout`: a server that starts makes the test fail, not hang).
TEST_F(Cli, ServeAndBenchRefuseNegativeAndNonFiniteNumbers) {
  std::filesystem::create_directories(path("models"));
  const std::string serve = "serve --models " + path("models") + " --listen 127.0.0.1:0 ";
  for (const std::string bad : {"--drain -5", "--drain nan", "--drain inf", "--drain 1e9", "--poll nan", "--poll -1",
                                "--uncertain-width nan", "--uncertain-width -0.1"}) {
    const CommandResult r = run(serve + bad, "timeout 20");
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    const std::string flag = bad.substr(0, bad.find(' '));
    EXPECT_EQ(r.output.rfind("mufric: error: " + flag + ": Value ", 0), 0u) << bad << ": " << r.output;
    EXPECT_EQ(line_count(r.output), 1u) << r.output;
  }
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("law.h5")).exit_code, 0);
  for (const std::string bad : {"--seconds nan", "--seconds -1", "--seconds inf", "--batch 0", "--batch 64 -1",
                                "--replay 0,5", "--replay 5,-1"}) {
    const CommandResult r = run("bench --model " + path("law.h5") + " " + bad, "timeout 20");
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    const std::string flag = bad.substr(0, bad.find(' '));
    EXPECT_EQ(r.output.rfind("mufric: error: " + flag + ": ", 0), 0u) << bad << ": " << r.output;  // before the table
  }
  EXPECT_NE(run("law coulomb --mu nan --out " + path("nan.h5")).exit_code, 0);
}

TEST_F(Cli, MicroProfileReportsRoughnessAndFitError) {
  CommandResult r = run("micro profile --ra 0.25um --correlation 1um --length 20um --seed 3 --out " + path("fit.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("Ra 0.25um"), std::string::npos) << r.output;  // scaled to the request exactly
  EXPECT_NE(r.output.find("max error"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(path("fit.csv")));
  // The written data, read back as a measured profile (microns in the header), fits the same way.
  std::ofstream(path("measured.csv")) << "x[um],height[um]\n";
  {
    std::ifstream in(path("fit.csv"));
    std::ofstream out(path("measured.csv"), std::ios::app);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) out << line.substr(0, line.find(',', line.find(',') + 1)) << "\n";
  }
  r = run("micro profile --csv " + path("measured.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("Ra 0.25um"), std::string::npos) << r.output;
  r = run("micro profile --ra 0.2 --length 10um");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--ra"), std::string::npos) << r.output;
  std::ofstream(path("bad.csv")) << "x[um],height[um]\n0,0\n1,0\n2,0\n2,1\n4,0\n5,0\n6,0\n7,0\n8,0\n9,0\n10,0\n";
  r = run("micro profile --csv " + path("bad.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("bad.csv:5"), std::string::npos) << r.output;
}

// Issue 30: `--correlation 100um --length 10um` was accepted and printed a correlation length of
// 1.9um, the period's figure. Impossible option combinations are refused before anything is printed,
// naming the options; the limits themselves (a fifth of the period, one sample spacing) pass.
TEST_F(Cli, MicroProfileRefusesOptionsNoProfileCanMeet) {
  CommandResult r = run("micro profile --correlation 100um --length 10um");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("mufric: error: --correlation 100um is too long for --length 10um"), std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("profile synthetic"), std::string::npos) << r.output;  // nothing printed first
  r = run("micro profile --correlation 2.5um --length 10um");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--correlation 2.5um"), std::string::npos) << r.output;
  r = run("micro profile --correlation 2um --length 10um");  // five correlation lengths: allowed
  EXPECT_EQ(r.exit_code, 0) << r.output;

  // Samples farther apart than the correlation length: white noise, not the requested roughness.
  r = run("micro profile --correlation 0.1um --length 10um --samples 64 --control-points 8");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--samples 64"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--correlation 0.1um"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("at least 100"), std::string::npos) << r.output;
  r = run("micro profile --correlation 0.1um --length 10um --samples 100 --control-points 8");  // one per length
  EXPECT_EQ(r.exit_code, 0) << r.output;

  // The fit's limits, refused before the roughness is printed and named by their options.
  r = run("micro profile --samples 20");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--control-points 64"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--samples is 20"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("profile synthetic"), std::string::npos) << r.output;
  r = run("micro profile --control-points 3 --degree 5");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--control-points 3 cannot carry --degree 5"), std::string::npos) << r.output;
  r = run("micro profile --length -10um");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--length"), std::string::npos) << r.output;

  // Synthetic options beside a measured profile, and a measured profile's period without one, were
  // silently ignored.
  std::ofstream(path("flat.csv")) << "x[um],height[um]\n0,0\n1,0\n";
  r = run("micro profile --csv " + path("flat.csv") + " --length 20um");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--length"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--csv"), std::string::npos) << r.output;
  r = run("micro profile --period 20um");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--period"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--csv"), std::string::npos) << r.output;
}

TEST_F(Cli, MicroRunWritesItsResultAndNamesBadSceneKeys) {
  const std::string small =
      " --set discretisation.elements_x=32 --set discretisation.elements_y=4"
      " --set geometry.chip_surface.fit.control_points=32 --set geometry.tool_surface.fit.control_points=32"
      " --set load.ramp=8ns --set protocol.press_hold=4ns --set protocol.run_in=0.05um --set protocol.window=0.1um"
      " --set protocol.step_distance=25nm --set protocol.phases=2 --set protocol.realisations=1 --quiet";
  CommandResult r = run("micro run --out " + path("run") + small);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("mu = "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(standard error"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("| 2 | 0.500 |"), std::string::npos) << r.output;  // the second tool phase's row
  for (const char* file : {"result.json", "chip.vtu", "tool.vtu", "contact.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(path("run") + "/" + file)) << file;
  }
  std::ifstream in(path("run") + "/result.json");
  std::string json, line;
  while (std::getline(in, line)) json += line;
  // contact.csv is the first draw's final contact point by point: Σ p w n over its rows is the
  // contact force that draw's last step recorded in result.json.
  {
    const nlohmann::json result = nlohmann::json::parse(json);
    std::ifstream csv(path("run") + "/contact.csv");
    std::getline(csv, line);
    EXPECT_EQ(line, "reference_x_m,weight_m,x_m,y_m,gap_m,pressure_pa,shear_pa,normal_x,normal_y,wetted");
    double force_x = 0.0, force_y = 0.0;
    int rows = 0, searched = 0;
    while (std::getline(csv, line)) {
      std::vector<std::string> field;
      std::stringstream row(line);
      for (std::string f; std::getline(row, f, ',');) field.push_back(f);
      ASSERT_EQ(field.size(), 10U) << line;
      EXPECT_EQ(field[9], "0") << "a dry run wets no spot: " << line;
      ++rows;
      searched += !field[4].empty();
      // (pressure n + shear t) × reference length, N/m, with t = (−n_y, n_x)
      const double weight = std::stod(field[1]), pressure = std::stod(field[5]), shear = std::stod(field[6]);
      const double nx = std::stod(field[7]), ny = std::stod(field[8]);
      force_x += weight * (pressure * nx - shear * ny);
      force_y += weight * (pressure * ny + shear * nx);
    }
    EXPECT_GT(rows, 0);
    EXPECT_GT(searched, 0);
    const auto& last = result["draws"][0]["history"].back();
    const double fx = last["force_x_n_per_m"], fy = last["force_y_n_per_m"];
    EXPECT_NEAR(force_x, fx, 1e-9 * std::abs(fy));
    EXPECT_NEAR(force_y, fy, 1e-9 * std::abs(fy));
  }
  EXPECT_NE(json.find("\"history\""), std::string::npos);
  EXPECT_NE(json.find("\"mu_std_error\""), std::string::npos);
  EXPECT_NE(json.find("\"block_means\""), std::string::npos);
  // Seed 000's protocol by name: one draw, no error bar.
  r = run("micro run --out " + path("run1") + small + " --set protocol.name=seed-000 --set time.duration=12ns"
          " --set time.average_from=8ns");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("seed 000 protocol: one draw"), std::string::npos) << r.output;
  EXPECT_NE(json.find("\"contact_area_fraction\""), std::string::npos);
  r = run("micro run --out " + path("run2") + " --set load.presure=1GPa");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("load.presure: unknown key"), std::string::npos) << r.output;
  r = run("micro run --out " + path("run3") + " --set physics=wet");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("physics"), std::string::npos) << r.output;
}

// A scene small enough that a sample takes a fraction of a second: press-slide with one tool at two
// phases, pressed 3 + 3 ns, slid 0.15 um.
const std::string kTinyScene =
    " --set geometry.chip_surface.fit.control_points=16 --set geometry.tool_surface.fit.control_points=16"
    " --set discretisation.elements_x=16 --set discretisation.elements_y=4 --set load.ramp=3ns"
    " --set protocol.press_hold=3ns --set protocol.run_in=0.05um --set protocol.window=0.1um"
    " --set protocol.step_distance=50nm --set protocol.phases=2 --set protocol.realisations=1";

// The same command gives the same μ to the last digit, with the draws side by side on two threads.
// OpenBLAS's threads, shared by the two draws, changed the last digits of this run from run to run
// (2 of 6 differed beside a running ctest; 8 of 8 agree with the fix), and a lubricated run turns
// those into another μ (−0.0021 once, −0.0130 twice on this scene), which made the dry-and-lubricated
// serving test below fail now and then. Whether two BLAS calls overlap is up to the scheduler: without
// the fix this test fails often under load (as in ctest -j2), seldom on an idle machine.
TEST_F(Cli, MicroRunRepeatsItselfWithDrawsSideBySide) {
  if (MUFRIC_EXE_SANITIZED) GTEST_SKIP() << "six micro-model runs: release build only";
  ::setenv("OMP_NUM_THREADS", "2", 1);
  std::vector<std::string> mu;
  for (int repeat = 0; repeat < 6; ++repeat) {
    const std::string out = path("repeat" + std::to_string(repeat));
    const CommandResult r = run("micro run --quiet --out " + out + kTinyScene);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream in(out + "/result.json");
    std::string json, line;
    while (std::getline(in, line)) json += line + "\n";
    EXPECT_NE(json.find("\"threads\": 2"), std::string::npos) << "the draws did not run side by side";
    const auto at = json.find("\n  \"mu\": ");  // the measurement's, not a step's
    ASSERT_NE(at, std::string::npos) << json.substr(0, 400);
    mu.push_back(json.substr(at, json.find_first_of(",\n", at) - at));
  }
  ::unsetenv("OMP_NUM_THREADS");
  for (size_t repeat = 1; repeat < mu.size(); ++repeat) EXPECT_EQ(mu[repeat], mu[0]) << "run " << repeat;
}

TEST_F(Cli, MicroConvergeDoublesTheRequestedDirection) {
  // Tolerance 1: the first refinement converges, so the table has two levels.
  CommandResult r = run("micro converge --direction y --max-levels 1 --tolerance 1" + kTinyScene);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // 16 × 4 elements, then 16 × 8 (degree 2: (16) × (4 + 2) and (16) × (8 + 2) control points, 2 dofs each).
  EXPECT_NE(r.output.find("| 0 | 16 x 4 | 192 |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("| 1 | 16 x 8 | 320 |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("converged at level 1"), std::string::npos) << r.output;
  // A tolerance no change can meet: not converged, exit code 3.
  r = run("micro converge --direction x --max-levels 1 --tolerance 1e-6" + kTinyScene);
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("| 1 | 32 x 4 | 384 |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not converged within 1 refinements"), std::string::npos) << r.output;
  // The protocol's own choices converge the same way: halving the sliding step.
  r = run("micro converge --parameter step --max-levels 1 --tolerance 1" + kTinyScene);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("| 1 | 25 nm |"), std::string::npos) << r.output;
  r = run("micro converge --direction z" + kTinyScene);
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("--direction"), std::string::npos) << r.output;
}

TEST_F(Cli, FluidCheckCavityPrintsBothCentreLinesBesideGhia) {
  CommandResult r = run("micro fluid-check cavity --reynolds 100 --elements 16");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("centre_line,x[L],y[L],velocity[U],ghia1982[U]"), std::string::npos) << r.output;
  // Ghia's minimum of v on y = 1/2 (x = 103/128) and the lid row.
  EXPECT_NE(r.output.find("v_on_y=0.5,0.804688,0.500000,"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("u_on_x=0.5,0.500000,1.000000,1.000000,1.000000"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("largest |velocity - Ghia et al. 1982|"), std::string::npos) << r.output;
  // Another Reynolds number: no reference column, still both lines.
  r = run("micro fluid-check cavity --reynolds 10 --elements 8");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("u_on_x=0.5,0.500000,1.000000,1.000000,\n"), std::string::npos) << r.output;
  r = run("micro fluid-check cavity --elements 2");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--elements"), std::string::npos) << r.output;
}

TEST_F(Cli, CorruptModelIsRefused) {
  std::ofstream(path("bad.h5")) << "not a model";
  const CommandResult r = run("predict --model " + path("bad.h5") + " --p 800MPa --v 100m/min --T 500C");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("not an HDF5 file"), std::string::npos) << r.output;
}

TEST_F(Cli, DatasetPlanRunResumeMergeAndTrain) {
  CommandResult r = run("dataset plan --out " + path("plan.h5") + " --samples 6 --design lhs --seed 4 --p 500MPa:900MPa" + kTinyScene);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("500MPa .. 900MPa"), std::string::npos) << r.output;
  // Two shards; the first stops after one sample and is resumed.
  r = run("dataset run --plan " + path("plan.h5") + " --db " + path("s0.h5") + " --shard 0/2 --limit 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("3 plan rows in this shard, 0 already done, 1 run now"), std::string::npos) << r.output;
  r = run("dataset run --plan " + path("plan.h5") + " --db " + path("s0.h5") + " --shard 0/2");
  EXPECT_NE(r.output.find("1 already done, 2 run now"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("sample 1/2 (plan row "), std::string::npos) << r.output;  // plain progress lines off a terminal
  ASSERT_EQ(run("dataset run --plan " + path("plan.h5") + " --db " + path("s1.h5") + " --shard 1/2 --jobs 2").exit_code, 0);
  r = run("dataset merge --out " + path("all.h5") + " " + path("s0.h5") + " " + path("s1.h5") + " " + path("s1.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("9 samples read, 3 duplicates removed -> 6 samples"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 of 6 plan rows not yet run"), std::string::npos) << r.output;
  r = run("dataset status " + path("all.h5"));
  EXPECT_NE(r.output.find("samples: 6 (6 converged, 0 outside the model, 0 failed); 0 of 6 plan points not yet run"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("design latin-hypercube (seed 4)"), std::string::npos) << r.output;
  r = run("dataset status " + path("s1.h5"));  // one shard: the other rows are not run (in this file)
  EXPECT_NE(r.output.find("3 of 6 plan points not yet run"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("draws independent"), std::string::npos) << r.output;
  // Independent draws: stochastic kriging, the mean's interval, and the patch scatter served beside it.
  r = run("train --data " + path("all.h5") + " --out " + path("gp.h5") + " --restarts 1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("stochastic kriging: 6 samples of independent draws"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("interval: std = sqrt(model variance): where the micro-model's mu averaged over all draws"),
            std::string::npos) << r.output;
  r = run("predict --model " + path("gp.h5") + " --p 700MPa --v 100m/min --T 500C");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("patch scatter "), std::string::npos) << r.output;
  r = run("describe " + path("gp.h5"));
  EXPECT_NE(r.output.find("patch scatter: a GP of the log per-draw variance"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("fast evaluator of its log variance within"), std::string::npos) << r.output;  // train built it
  // The same data trained as common draws (as every dataset from before issue 33 is): one GP, the
  // samples' scatter added to the interval, no patch scatter.
  r = run("train --data " + path("all.h5") + " --out " + path("gp-common.h5") + " --restarts 1 --no-stochastic-kriging");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("only a dataset of independent draws"), std::string::npos) << r.output;
  r = run("predict --model " + path("gp-common.h5") + " --p 700MPa --v 100m/min --T 500C");
  EXPECT_EQ(r.output.find("patch scatter"), std::string::npos) << r.output;
  // A database of this plan refuses another scene.
  r = run("dataset run --plan " + path("plan.h5") + " --db " + path("s0.h5") + " --shard 0/2 --set load.ramp=2ns");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("different scene"), std::string::npos) << r.output;
}

// A lubricated dataset goes through the dry chain unchanged — plan, run, train — and one server
// answers the dry and the lubricated model side by side, each by its name (three micro-model runs
// of the tiny scene per physics, at 300–400 MPa where the lubricant changes μ most; common draws, so
// that dry and lubricated samples see the same surfaces: with its own surfaces a tiny scene's
// sample may slide to a slightly negative μ, outside the model's range).
TEST_F(Cli, DryAndLubricatedModelsAreServedSideBySide) {
  // Lubricated micro-model runs take minutes under the sanitizers (over CTest's 600 s for three); the
  // sanitizer build runs the film and coupling code nowhere else either (its tests are labelled micro).
  if (MUFRIC_EXE_SANITIZED) GTEST_SKIP() << "lubricated micro-model runs: release build only";
  std::filesystem::create_directories(path("models"));
  for (const std::string physics : {"dry", "lubricated"}) {
    CommandResult r = run("dataset plan --out " + path(physics + "-plan.h5") +
                          " --samples 3 --design lhs --seed 1 --p 300MPa:400MPa --v 50m/min:100m/min --T 25C:200C" +
                          kTinyScene + " --set physics=" + physics + " --common-tools");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run("dataset run --plan " + path(physics + "-plan.h5") + " --db " + path(physics + ".h5"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run("dataset status " + path(physics + ".h5"));
    EXPECT_NE(r.output.find("samples: 3 (3 converged"), std::string::npos) << physics << ": " << r.output;
    EXPECT_NE(r.output.find("physics " + physics + ")"), std::string::npos) << r.output;
    r = run("train --data " + path(physics + ".h5") + " --out " + path("models/" + physics + ".h5"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // Common draws: the model says its interval keeps the shared scatter.
    EXPECT_NE(r.output.find("only a dataset of independent draws"), std::string::npos) << r.output;
  }
  ServeProcess server(path("models"), path("serve.log"), path("address"));
  ASSERT_FALSE(server.address().empty()) << "server did not start";
  std::map<std::string, double> mu;
  for (const std::string model : {"dry", "lubricated"}) {
    const CommandResult r = run("predict --model grpc://" + server.address() + "/" + model + " --p 350MPa --v 75m/min --T 100C");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto at = r.output.find("mu = ");
    ASSERT_NE(at, std::string::npos) << r.output;
    mu[model] = std::stod(r.output.substr(at + 5));
  }
  std::cout << "served mu at 350 MPa, 75 m/min, 100 C: dry " << mu["dry"] << ", lubricated " << mu["lubricated"] << "\n";
  EXPECT_GT(mu["dry"], 0.0);
  EXPECT_GT(mu["lubricated"], 0.0);
  EXPECT_NE(mu["dry"], mu["lubricated"]);
  EXPECT_EQ(server.stop(), 0);
}

TEST_F(Cli, DatasetErrorsNameTheFlag) {
  CommandResult r = run("dataset plan --out " + path("p.h5") + " --p 900MPa:500MPa");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--p '900MPa:500MPa'"), std::string::npos) << r.output;
  r = run("dataset plan --out " + path("p.h5") + " --design halton");
  EXPECT_NE(r.output.find("design 'halton'"), std::string::npos) << r.output;
  r = run("dataset plan --out " + path("p.h5") + " --set load.vertical_displacement=\\\"-1nm\\\" --set load.pressure=null");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("load.vertical_displacement"), std::string::npos) << r.output;  // null removed the pressure
  ASSERT_EQ(run("dataset plan --out " + path("p.h5") + " --samples 2" + kTinyScene).exit_code, 0);
  r = run("dataset run --plan " + path("p.h5") + " --db " + path("d.h5") + " --shard 2/2");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--shard '2/2'"), std::string::npos) << r.output;
}

// A calibration campaign's model (inputs p, v and a shear factor m, trained on a smooth synthetic μ),
// measurements made at m* = 0.55: `calibrate` finds m* inside its 95 % credible interval, writes the
// same posterior from the same seed, and refuses a row outside the box, a bad prior and chains too
// short to judge, each naming the cause; such a model is not served until it is calibrated.
TEST_F(Cli, CalibrateFindsTheShearFactorThatMadeTheMeasurements) {
  auto synthetic_mu = [](double p_mpa, double v_m_min, double m) {
    const double ps = (p_mpa - 300.0) / 1000.0, vs = (v_m_min - 22.5) / 177.5;
    return 0.1 + 0.5 * m * (1.0 - 0.3 * ps) - 0.05 * vs;
  };
  {
    std::ofstream train(path("campaign.csv"));
    train << "contact_pressure[MPa],sliding_velocity[m/min],shear_factor,mu\n";
    for (int i = 0; i < 64; ++i) {  // a 4 × 4 × 4 grid over the box
      const double p = 300.0 + 1000.0 * (i % 4) / 3.0, v = 22.5 + 177.5 * ((i / 4) % 4) / 3.0, m = 0.2 + 0.7 * (i / 16) / 3.0;
      train << p << "," << v << "," << m << "," << synthetic_mu(p, v, m) << "\n";
    }
    std::ofstream measured(path("measured.csv"));
    measured << "# synthetic: the campaign's mu at shear_factor 0.55,\n# stated SD 0.01\n"
             << "contact_pressure[MPa],sliding_velocity[m/min],mu,mu_sd\n";
    for (const auto& [p, v] : std::vector<std::pair<double, double>>{{400, 30}, {600, 120}, {800, 60}, {1000, 180}, {1200, 90}, {500, 150}}) {
      measured << p << "," << v << "," << synthetic_mu(p, v, 0.55) << ",0.01\n";
    }
  }
  CommandResult r = run("train --data " + path("campaign.csv") + " --out " + path("campaign.h5") + " --restarts 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run("predict --model " + path("campaign.h5") + " --p 800MPa --v 100m/min");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("'shear_factor' is a coefficient of the interface law"), std::string::npos) << r.output;
  r = run("describe " + path("campaign.h5"));  // describe shows it, and says why it is not served
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("not served: its input 'shear_factor' is a coefficient"), std::string::npos) << r.output;

  const std::string calibrate = "calibrate --model " + path("campaign.h5") + " --data " + path("measured.csv") +
                                " --walkers 12 --burn-in 300 --steps 1200 --seed 5 --out ";
  r = run(calibrate + path("posterior.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::istringstream lines(r.output);
  std::string line;
  double lo = 0.0, hi = 0.0;
  while (std::getline(lines, line)) {
    if (line.rfind("shear_factor ", 0) != 0) continue;
    std::istringstream fields(line);
    std::string name, dots;
    double mean = 0.0, sd = 0.0;
    fields >> name >> mean >> sd >> lo >> dots >> hi;
  }
  EXPECT_LE(lo, 0.55) << r.output;
  EXPECT_GE(hi, 0.55) << r.output;
  EXPECT_LT(hi - lo, 0.1) << r.output;  // six measurements of SD 0.01 pin m down
  EXPECT_NE(r.output.find("split-R^"), std::string::npos);
  const std::string posterior = read_text(path("posterior.csv"));
  EXPECT_NE(posterior.find("\nshear_factor\n"), std::string::npos);
  ASSERT_EQ(run(calibrate + path("again.csv")).exit_code, 0);
  EXPECT_EQ(read_text(path("again.csv")), posterior) << "the same seed, the same posterior";
  // --out is thinned evenly to --out-samples rows (issue 72: 75 MB by default); 0 writes every state.
  const auto rows_of = [](const std::string& text) { return std::count(text.begin(), text.end(), '\n') - 3; };  // two comment lines and the names
  ASSERT_EQ(run(calibrate + path("all.csv") + " --out-samples 0").exit_code, 0);
  const std::string all = read_text(path("all.csv"));
  ASSERT_GT(rows_of(all), 1000) << all.substr(0, 300);
  r = run(calibrate + path("thin.csv") + " --out-samples 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string thin = read_text(path("thin.csv"));
  EXPECT_LE(rows_of(thin), 100);
  EXPECT_GT(rows_of(thin), 50);
  EXPECT_NE(r.output.find("evenly thinned; --out-samples 0 for all"), std::string::npos) << r.output;
  // the thinned file's first sample row is the full chain's first, its second the stride-th
  const auto sample_row = [](const std::string& text, int k) {
    std::istringstream in(text);
    std::string line;
    for (int i = 0; i < 3 + k; ++i) std::getline(in, line);
    return line;
  };
  const long long stride = (rows_of(all) + 99) / 100;
  EXPECT_EQ(sample_row(thin, 1), sample_row(all, 1));
  EXPECT_EQ(sample_row(thin, 2), sample_row(all, static_cast<int>(1 + stride)));
  EXPECT_EQ(r.output.find("hardly inform"), std::string::npos) << "six rows of SD 0.01 inform m: " << r.output;
  EXPECT_NE(r.output.find("against 6 measurements in 1 data set,"), std::string::npos) << r.output;

  // One row with the discrepancy on: δ explains it alone and m keeps its prior, which calibrate says
  // (issue 72: exit 0 without a word, and "1 measurements").
  {
    std::ifstream full(path("measured.csv"));
    std::ofstream one(path("one.csv"));
    std::string line;
    for (int i = 0; i < 4 && std::getline(full, line); ++i) one << line << "\n";  // two comments, the header, one row
  }
  r = run("calibrate --model " + path("campaign.h5") + " --data " + path("one.csv") +
          " --discrepancy --walkers 16 --burn-in 300 --steps 1200 --seed 5");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("against 1 measurement in 1 data set,"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("warning: with the discrepancy on, 1 measurement cannot tell δ from the law"), std::string::npos)
      << r.output;
  // Six rows whose SD (0.5) dwarfs what m changes in μ: the posterior is the prior, and calibrate says so.
  {
    std::ifstream full(path("measured.csv"));
    std::ofstream vague(path("vague.csv"));
    for (std::string line; std::getline(full, line);) {
      vague << (line.size() > 5 && line.substr(line.size() - 5) == ",0.01" ? line.substr(0, line.size() - 5) + ",0.5" : line) << "\n";
    }
  }
  r = run("calibrate --model " + path("campaign.h5") + " --data " + path("vague.csv") + " --walkers 12 --burn-in 300 --steps 1200 --seed 5");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: shear_factor: its posterior SD is"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("of its prior's (uniform(0.2, 0.9) within the box): the measurements hardly inform it"), std::string::npos)
      << r.output;

  // The calibrated model: read from its file and served, the same μ both ways; describe shows its parts.
  std::filesystem::create_directories(path("served"));
  r = run(calibrate + path("posterior.csv") + " --model-out " + path("served/calibrated.h5") + " --no-fast-evaluator");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("calibrated model of contact_pressure sliding_velocity"), std::string::npos) << r.output;
  r = run("describe " + path("served/calibrated.h5"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("kind calibrated"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("interval at the box centre: mu "), std::string::npos) << r.output;
  // the file by its path and content (issue 72: a deleted temporary path was all a model said), its
  // provenance as the running text it is
  const std::string hash = run_shell("sha256sum " + path("measured.csv")).output.substr(0, 64);
  EXPECT_NE(r.output.find("measurements: " + path("measured.csv") + " (sha256 " + hash +
                          "): synthetic: the campaign's mu at shear_factor 0.55, stated SD 0.01\n"),
            std::string::npos)
      << r.output;
  // `upgrade` grids a calibrated model as it grids a GP, and strips the grid again.
  r = run("upgrade " + path("served/calibrated.h5") + " --out " + path("graded.h5") + " --fast-max-work 0.05");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fast evaluator (calibrated model): "), std::string::npos) << r.output;
  EXPECT_NE(run("describe " + path("graded.h5")).output.find("fast evaluator: grid"), std::string::npos);
  ASSERT_EQ(run("upgrade " + path("graded.h5") + " --no-fast-evaluator").exit_code, 0);
  EXPECT_NE(run("describe " + path("graded.h5")).output.find("no fast evaluator (the exact posterior predictive answers)"),
            std::string::npos);
  const CommandResult from_file = run("predict --model " + path("served/calibrated.h5") + " --p 700MPa --v 100m/min");
  ASSERT_EQ(from_file.exit_code, 0) << from_file.output;
  {
    ServeProcess server(path("served"), path("serve-calibrated.log"), path("address-calibrated"));
    ASSERT_FALSE(server.address().empty()) << "server did not start: " << read_text(path("serve-calibrated.log"));
    const CommandResult served = run("predict --model grpc://" + server.address() + "/calibrated --p 700MPa --v 100m/min");
    ASSERT_EQ(served.exit_code, 0) << served.output;
    const auto mu_of = [](const std::string& text) { return text.substr(text.find("mu = "), text.find("  std")  - text.find("mu = ")); };
    EXPECT_EQ(mu_of(served.output), mu_of(from_file.output)) << served.output << from_file.output;
    EXPECT_EQ(server.stop(), 0);
  }

  r = run("calibrate --model " + path("campaign.h5") + " --data " + path("measured.csv") + " --steps 8 --burn-in 0 --max-steps 0 --out " +
          path("short.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("the posterior is not usable, nothing written: shear_factor"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(path("short.csv")));

  std::ofstream(path("outside.csv")) << "contact_pressure[MPa],sliding_velocity[m/min],mu,mu_sd\n800,100,0.4,0.01\n1500,100,0.4,0.01\n";
  r = run("calibrate --model " + path("campaign.h5") + " --data " + path("outside.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("outside.csv line 3: contact_pressure 1500MPa lies outside the model's box 300MPa – 1300MPa"), std::string::npos) << r.output;
  r = run("calibrate --model " + path("campaign.h5") + " --data " + path("measured.csv") + " --fix shear_factor=0.5");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("every law coefficient of the model (shear_factor) is fixed or measured: nothing to calibrate"),
            std::string::npos) << r.output;  // held, nothing left to calibrate
  r = run("calibrate --model " + path("campaign.h5") + " --data " + path("measured.csv") + " --fix sliding_velocity=3m/s");
  EXPECT_NE(r.output.find("--fix 'sliding_velocity=3m/s': the measurements already give sliding_velocity"), std::string::npos)
      << r.output;
  std::ofstream(path("priors.json")) << R"({"parameters": {"shear_factor": {"uniform": [0.9, 0.2]}}})";
  r = run("calibrate --model " + path("campaign.h5") + " --data " + path("measured.csv") + " --priors " + path("priors.json"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("parameters.shear_factor.uniform"), std::string::npos) << r.output;
}

// Data a new user brings that cannot be calibrated, or should not be without a word (issue 63): each
// refusal names the real cause, each suspicion is a warning, and the output says how to read itself.
TEST_F(Cli, CalibrateRefusesWhatCannotBeFrictionAndNamesTheCause) {
  auto synthetic_mu = [](double p_mpa, double v_m_min, double m) {
    return 0.1 + 0.5 * m * (1.0 - 0.3 * (p_mpa - 300.0) / 1000.0) - 0.05 * (v_m_min - 22.5) / 177.5;
  };
  {
    std::ofstream train(path("campaign.csv")), plain(path("plain.csv"));
    train << "contact_pressure[MPa],sliding_velocity[m/min],shear_factor,mu\n";
    plain << "contact_pressure[MPa],sliding_velocity[m/min],mu\n";
    for (int i = 0; i < 64; ++i) {
      const double p = 300.0 + 1000.0 * (i % 4) / 3.0, v = 22.5 + 177.5 * ((i / 4) % 4) / 3.0, m = 0.2 + 0.7 * (i / 16) / 3.0;
      train << p << "," << v << "," << m << "," << synthetic_mu(p, v, m) << "\n";
      if (i < 16) plain << p << "," << v << "," << synthetic_mu(p, v, 0.5) << "\n";
    }
  }
  ASSERT_EQ(run("train --data " + path("campaign.csv") + " --out " + path("campaign.h5") + " --restarts 1").exit_code, 0);
  ASSERT_EQ(run("train --data " + path("plain.csv") + " --out " + path("plain.h5") + " --restarts 0").exit_code, 0);
  auto measurements = [&](const std::string& name, const std::string& header, const std::vector<std::string>& rows) {
    std::ofstream out(path(name));
    out << header << "\n";
    for (const std::string& row : rows) out << row << "\n";
    return path(name);
  };
  const std::string good = measurements("good.csv", "contact_pressure[MPa],sliding_velocity[m/min],mu,mu_sd",
                                        {"400,30,0.341,0.01", "800,60,0.318,0.01", "1200,90,0.296,0.01"});
  const std::string calibrate = "calibrate --model " + path("campaign.h5") + " --walkers 12 --burn-in 200 --steps 600 --data ";
  // A condition the data forget is an error naming its column, not a coefficient to calibrate.
  CommandResult r = run(calibrate + measurements("forgot.csv", "contact_pressure[MPa],mu,mu_sd", {"400,0.34,0.01"}));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("the measurements give no sliding_velocity, a condition of the model: add a column "
                          "sliding_velocity[m/min]"), std::string::npos) << r.output;
  // Values that cannot be friction, or that nothing in the box reaches.
  r = run(calibrate + measurements("negative.csv", "contact_pressure[MPa],sliding_velocity[m/min],mu,mu_sd", {"400,30,-0.3,0.01"}));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("negative.csv line 2: μ -0.3 is negative"), std::string::npos) << r.output;
  r = run(calibrate + measurements("five.csv", "contact_pressure[MPa],sliding_velocity[m/min],mu,mu_sd", {"400,30,5,0.05"}));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("five.csv line 2: μ 5 lies"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no coefficient in the model's box reaches it"), std::string::npos) << r.output;
  // Suspicious but allowed: identical rows, a prior mostly outside the box.
  std::ofstream(path("edge.json")) << R"({"parameters": {"shear_factor": {"normal": [0.95, 0.1]}}})";
  r = run(calibrate + measurements("twice.csv", "contact_pressure[MPa],sliding_velocity[m/min],mu,mu_sd",
                                   {"400,30,0.341,0.01", "400,30,0.341,0.01", "800,60,0.318,0.01"}) +
          " --priors " + path("edge.json"));
  EXPECT_NE(r.output.find("warning: twice.csv line 2 and twice.csv line 3 are identical"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("warning: prior of shear_factor: only 31 % of its prior normal(0.95, 0.1) lies inside the model's box"),
            std::string::npos) << r.output;
  // A held value outside the box, a model with nothing to calibrate.
  r = run(calibrate + good + " --fix shear_factor=1.5");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--fix 'shear_factor=1.5': 1.5 is outside the model's box for shear_factor (0.2 – 0.9)"),
            std::string::npos) << r.output;
  r = run("calibrate --model " + path("plain.h5") + " --data " + good);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("this model has no law coefficient to calibrate (its inputs: contact_pressure, sliding_velocity)"),
            std::string::npos) << r.output;
  // The reader's guide, and split-R^ to enough digits to see why 1.05042 fails 1.05.
  r = run("calibrate --model " + path("campaign.h5") + " --walkers 12 --burn-in 300 --steps 1200 --seed 5 --data " + good);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("how to read it: split-R^ compares"), std::string::npos) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("shear_factor +[0-9.]+ +[0-9.]+ +[0-9.]+ \\.\\. [0-9.]+ +1\\.[0-9]{4} ")))
      << r.output;
}

// A plan varies a law coefficient as an input when the scene's law reads it, and refuses otherwise.
TEST_F(Cli, DatasetPlanVariesALawCoefficientTheScenesLawReads) {
  CommandResult r = run("dataset plan --out " + path("p.h5") + " --samples 4 --shear-factor 0.2:0.9" + kTinyScene);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("contact.shear_factor, which has no effect"), std::string::npos) << r.output;
  r = run("dataset plan --out " + path("p.h5") + " --samples 4 --shear-factor 0.2:0.9 --set contact.law=\\\"shear-factor\\\" "
          "--set contact.shear_factor=0.5" + kTinyScene);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("shear_factor"), std::string::npos) << r.output;
}

TEST_F(Cli, DatasetRefineRunsWhereTheSurrogateIsUncertain) {
  ASSERT_EQ(run("dataset plan --out " + path("plan.h5") + " --samples 6 --p 700MPa:1300MPa" + kTinyScene).exit_code, 0);
  ASSERT_EQ(run("dataset run --plan " + path("plan.h5") + " --db " + path("db.h5")).exit_code, 0);
  // Candidates may also come from the server's log of uncertain queries (unit header, extra columns).
  std::ofstream(path("uncertain.csv")) << "contact_pressure[Pa],sliding_velocity[m/s],temperature[K],ci95_width\n"
                                           "1.0e9,1.5,700,0.3\n2.0e9,1.5,700,0.3\n";  // the second lies outside the box
  CommandResult r = run("dataset refine --db " + path("db.h5") + " --budget 3 --batch 2 --restarts 0 --model-out " +
                        path("gp.h5") + " --candidates " + path("uncertain.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("round 3: "), std::string::npos) << r.output;  // 2 + 1 runs, a GP after each round
  EXPECT_NE(r.output.find("3 micro-model runs spent of a budget of 3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("pick 2: plan row 7"), std::string::npos) << r.output;  // picks extend the plan
  // Independent draws: picked by the variance of the mean each removes over the box.
  EXPECT_NE(r.output.find("of the mean variance over the box"), std::string::npos) << r.output;
  r = run("dataset merge --out " + path("check.h5") + " " + path("db.h5"));
  EXPECT_NE(r.output.find(": 1 file, "), std::string::npos) << r.output;  // not "1 files" (issue 30)
  EXPECT_NE(r.output.find("-> 9 samples"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 of 9 plan rows not yet run"), std::string::npos) << r.output;
  EXPECT_NE(run("dataset status " + path("db.h5")).output.find("design sobol+active (seed 0)"), std::string::npos);
  EXPECT_EQ(run("describe " + path("gp.h5")).exit_code, 0);
}

// --grow-box: the plan's box grows toward the logged queries outside it, to the coverage quantile per
// side (0.75 of {1, 1, 2, 3} GPa is 2 GPa: the 3 GPa spike is left out), the change is recorded and
// shown, and growing again toward the same rows changes nothing.
TEST_F(Cli, DatasetRefineGrowsTheBoxTowardTheLoggedQueries) {
  ASSERT_EQ(run("dataset plan --out " + path("plan.h5") + " --samples 4 --p 700MPa:1300MPa" + kTinyScene).exit_code, 0);
  ASSERT_EQ(run("dataset run --plan " + path("plan.h5") + " --db " + path("db.h5")).exit_code, 0);
  std::ofstream(path("log.csv")) << "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],ci95_width,outside_inputs\n"
                                     "2000,60,400,0.01,1\n3000,60,400,0.01,1\n1000,6,400,0.01,1\n1000,6,400,0.01,1\n";
  CommandResult r = run("dataset refine --db " + path("db.h5") + " --budget 1 --batch 1 --restarts 0 --grow-box " +
                        "--grow-coverage 0.75 --candidates " + path("log.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("grown by dataset refine --grow-box (coverage 0.75) toward 4 of 4 rows"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("-> contact_pressure 7e+08..2e+09 Pa, sliding_velocity 0.1..3.33333 m/s"), std::string::npos)
      << r.output;
  const CommandResult status = run("dataset status " + path("db.h5"));
  EXPECT_NE(status.output.find("  box 20"), std::string::npos) << status.output;  // the record, with its date
  EXPECT_NE(status.output.find("samples: 5 ("), std::string::npos) << status.output;  // 4 planned + 1 pick
  // Growing again toward the same rows changes nothing and says so.
  r = run("dataset refine --db " + path("db.h5") + " --budget 0 --restarts 0 --grow-box --grow-coverage 0.75 --candidates " +
          path("log.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the box already covers the candidates"), std::string::npos) << r.output;
  EXPECT_NE(run("dataset refine --db " + path("db.h5") + " --budget 0 --grow-box").exit_code, 0);  // needs --candidates
}

// --sample-timeout: a sample still running after the limit stops and is recorded as failed, saying
// where it stopped; --retry-failed without the limit then completes it.
TEST_F(Cli, DatasetRunStopsASampleThatOutrunsItsTimeLimit) {
  ASSERT_EQ(run("dataset plan --out " + path("plan.h5") + " --samples 2" + kTinyScene).exit_code, 0);
  CommandResult r = run("dataset run --plan " + path("plan.h5") + " --db " + path("db.h5") + " --sample-timeout 0.001");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(0 converged, 2 failed)"), std::string::npos) << r.output;
  const CommandResult status = run("dataset status " + path("db.h5"));
  EXPECT_NE(status.output.find("wall-time limit of 0.001 s reached at t = "), std::string::npos) << status.output;
  r = run("dataset run --plan " + path("plan.h5") + " --db " + path("db.h5") + " --retry-failed");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(2 converged, 0 failed)"), std::string::npos) << r.output;
}

// kill -9 in the middle of a run loses at most the samples in flight: the database stays readable
// and a second run completes the plan with every row once.
TEST_F(Cli, DatasetRunSurvivesKillNine) {
  const std::string slower = kTinyScene + " --set protocol.window=0.3um";
  ASSERT_EQ(run("dataset plan --out " + path("plan.h5") + " --samples 6 --design sobol" + slower).exit_code, 0);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    freopen(path("run.log").c_str(), "w", stdout);
    execl(MUFRIC_EXE, MUFRIC_EXE, "dataset", "run", "--plan", path("plan.h5").c_str(), "--db", path("db.h5").c_str(),
          "--threads", "1", static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until two samples are recorded, then kill without warning. Up to 300 s: under the sanitizers
  // on a busy 2-core machine two tiny samples took more than the 30 s this waited before.
  bool recorded = false;
  for (int i = 0; i < 6000 && !recorded; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::ifstream log(path("run.log"));
    for (std::string line; std::getline(log, line);) recorded = recorded || line.rfind("sample 2/6", 0) == 0;
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(recorded) << "the run did not record two samples";
  CommandResult r = run("dataset merge --out " + path("check.h5") + " " + path("db.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.output;  // readable after the kill
  EXPECT_EQ(r.output.find(" 0 samples read"), std::string::npos) << r.output;
  r = run("dataset run --plan " + path("plan.h5") + " --db " + path("db.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find(" 0 already done"), std::string::npos) << r.output;
  r = run("dataset merge --out " + path("check.h5") + " " + path("db.h5"));
  EXPECT_NE(r.output.find("0 duplicates removed -> 6 samples"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 of 6 plan rows not yet run"), std::string::npos) << r.output;
}

// The on-line learner end to end on a simulator campaign (the shipped model standing in for the
// micro-model): a server's log of queries below the box; `learn run` killed with -9 as it plans and
// again as it trains, resumed each time, finishes its round with every plan row run once and a
// published version; status says so; rollback serves the first version's bytes again; a quiet log
// rests; another simulator's runs are refused before they start.
// A learner over a 16-sample campaign of the shipped model as simulator, its log holding six queries
// below the box (p 300-400 MPa); returns `learn init`'s output.
std::string set_up_learner(const std::filesystem::path& dir, const std::string& simulator) {
  const auto path = [&dir](const std::string& name) { return (dir / name).string(); };
  EXPECT_EQ(run("dataset plan --out " + path("plan.h5") + " --samples 16 --p 500MPa:1100MPa --v 50m/min:150m/min --T 200C:700C").exit_code, 0);
  EXPECT_EQ(run("dataset run --plan " + path("plan.h5") + " --db " + path("db.h5") + " --simulator " + simulator).exit_code, 0);
  std::filesystem::create_directories(path("served"));
  std::filesystem::create_directories(path("logs"));
  EXPECT_EQ(run("train --data " + path("db.h5") + " --out " + path("served/gp.h5") + " --restarts 0").exit_code, 0);
  {
    std::ofstream log(path("logs/gp.csv"));
    log << "contact_pressure[Pa],sliding_velocity[m/s],temperature[K],ci95_width,outside_inputs\n";
    for (int i = 0; i < 6; ++i) log << 300e6 + 20e6 * i << ",1.5,700,0.1,1\n";
    std::ofstream(path("logs/gp.outside.json")) << "{\"queries\": 60}";
  }
  const CommandResult r = run("learn init " + path("learner") + " --db " + path("db.h5") + " --model " + path("served/gp.h5") +
                              " --log " + path("logs/gp.csv") + " --round-samples 4 --budget-core-hours 1 --restarts 0");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.output;
}

TEST_F(Cli, LearnerSurvivesKillNineAndPublishesAGatedRound) {
  const std::string simulator = MUFRIC_SOURCE_DIR "/models/dry_default.h5";
  CommandResult r{0, set_up_learner(dir_, simulator)};
  const std::string first_version = r.output.substr(r.output.find("serving version ") + 16, 16);
  for (const char* kill_after : {"planned 4 runs", "training on", "gating"}) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      freopen(path("learn.log").c_str(), "w", stdout);
      execl(MUFRIC_EXE, MUFRIC_EXE, "learn", "run", path("learner").c_str(), "--simulator", simulator.c_str(),
            static_cast<char*>(nullptr));
      _exit(127);
    }
    bool seen = false;
    for (int i = 0; i < 6000 && !seen; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      std::ifstream log(path("learn.log"));
      for (std::string line; std::getline(log, line);) seen = seen || line.find(kill_after) != std::string::npos;
    }
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(seen) << kill_after << ": " << read_text(path("learn.log"));
  }
  r = run("learn run " + path("learner") + " --simulator " + simulator);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run("learn status " + path("learner"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("round 1: done; 6 logged rows (10 % of queries), plan rows 16-19"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("published "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("round 2"), std::string::npos) << r.output;  // the resumed round was not planned twice
  r = run("dataset merge --out " + path("check.h5") + " " + path("db.h5"));
  EXPECT_NE(r.output.find("0 duplicates removed -> 20 samples"), std::string::npos) << r.output;
  EXPECT_NE(run("describe " + path("served/gp.h5")).output.find("contact_pressure   [300MPa, 1100MPa]"), std::string::npos);
  r = run("learn run " + path("learner") + " --simulator " + simulator);
  EXPECT_NE(r.output.find("resting: no query logged"), std::string::npos) << r.output;
  r = run("learn rollback " + path("learner") + " " + first_version);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(run("describe " + path("served/gp.h5")).output.find("contact_pressure   [500MPa, 1100MPa]"), std::string::npos);
  r = run("learn rollback " + path("learner") + " 0123456789abcdef");
  EXPECT_NE(r.output.find("version 0123456789abcdef: not kept by this learner"), std::string::npos) << r.output;
  // Another simulator than the campaign's: refused before any run.
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("other.h5")).exit_code, 0);
  {
    std::ofstream log(path("logs/gp.csv"), std::ios::app);
    for (int i = 0; i < 6; ++i) log << 250e6 << ",1.5,700,0.1,1\n";
  }
  r = run("learn run " + path("learner") + " --simulator " + path("other.h5"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("its samples were made by another simulator"), std::string::npos) << r.output;
}

// A learner stopped after it published a round and before it recorded so (the served file already
// the candidate, the state still at the gate step) carries out the decision it recorded instead of
// gating the candidate against itself: it was kept aside as "adding no converged point" (found by
// the kill -9 test above under ASan, where the stop fell there).
TEST_F(Cli, ALearnerStoppedBetweenPublishingAndRecordingItKeepsThePublication) {
  const std::string simulator = MUFRIC_SOURCE_DIR "/models/dry_default.h5";
  set_up_learner(dir_, simulator);
  CommandResult r = run("learn run " + path("learner") + " --simulator " + simulator);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_NE(r.output.find("round 1: published "), std::string::npos) << r.output;
  const std::string served_bytes = read_text(path("served/gp.h5"));
  nlohmann::json state = nlohmann::json::parse(read_text(path("learner/learn.json")));
  ASSERT_EQ(state["rounds"].back()["step"], "done");
  state["rounds"].back()["step"] = "gate";  // the stop: the copy done, its record not written
  state["rounds"].back().erase("finished_utc");
  std::ofstream(path("learner/learn.json")) << state.dump(2);
  r = run("learn run " + path("learner") + " --simulator " + simulator);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("round 1: carrying out the gate's decision"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("round 1: published "), std::string::npos) << r.output;
  EXPECT_EQ(read_text(path("served/gp.h5")), served_bytes);
  r = run("learn status " + path("learner"));
  EXPECT_NE(r.output.find("published "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("kept aside"), std::string::npos) << r.output;
}

// A learner round through Slurm whose controller stops answering for a while (slurmctld restarting):
// the learner waits for the submitted jobs instead of taking them for gone and submitting the round
// again. Slurm is faked on PATH: sbatch runs the project's job scripts in the background
// (deploy/slurm/submit-dataset.sh submits them unchanged) and squeue fails like an unreachable
// controller for its first three calls, then answers from the jobs' state.
TEST_F(Cli, LearnerWaitsForSlurmJobsWhileTheControllerDoesNotAnswer) {
  const std::string simulator = MUFRIC_SOURCE_DIR "/models/dry_default.h5";
  set_up_learner(dir_, simulator);
  const std::string fake = path("fake-slurm");
  std::filesystem::create_directories(fake);
  std::ofstream(fake + "/sbatch") << R"SH(#!/bin/bash
# fake sbatch: the job (array tasks one after another) in the background; --dependency waits for the array
n=$(( $(cat "$FAKE_SLURM/submitted" 2>/dev/null || echo 0) + 1 )); echo $n > "$FAKE_SLURM/submitted"
chdir=. array= after=
for a; do case $a in --chdir=*) chdir=${a#*=};; --array=*) array=${a#*=};; --dependency=afterok:*) after=${a#*:};; esac; done
script=${!#}
id=$((100 + n))
(
  cd "$chdir"
  for ((tries = 0; tries < 1200; tries++)); do [[ -z $after || -e $FAKE_SLURM/$after.done ]] && break; sleep 0.1; done
  [[ -z $after || -e $FAKE_SLURM/$after.done ]] || exit 1  # the array never ended (a failed test): no orphan
  sleep 1  # still running when the learner first asks
  if [[ -n $array ]]; then
    for ((i = ${array%-*}; i <= ${array#*-}; i++)); do
      SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_MIN=${array%-*} SLURM_ARRAY_TASK_COUNT=$((${array#*-} - ${array%-*} + 1)) \
        bash "$script" > "task-$i.out" 2>&1
    done
  else
    bash "$script" > "merge.out" 2>&1
  fi
  touch "$FAKE_SLURM/$id.done"
) > /dev/null 2>&1 &
echo $id
)SH";
  std::ofstream(fake + "/squeue") << R"SH(#!/bin/bash
# fake squeue -h -j ID -o %r: three calls as an unreachable controller, then the job's state
n=$(( $(cat "$FAKE_SLURM/asked" 2>/dev/null || echo 0) + 1 )); echo $n > "$FAKE_SLURM/asked"
if ((n <= 3)); then echo "squeue: error: slurm_load_jobs error: Unable to contact slurm controller (connect failure)" >&2; exit 1; fi
[[ -e $FAKE_SLURM/$3.done ]] && { echo "slurm_load_jobs error: Invalid job id specified" >&2; exit 1; }
echo None
)SH";
  std::filesystem::permissions(fake + "/sbatch", std::filesystem::perms::owner_all, std::filesystem::perm_options::add);
  std::filesystem::permissions(fake + "/squeue", std::filesystem::perms::owner_all, std::filesystem::perm_options::add);
  const CommandResult r = run("learn run " + path("learner") + " --simulator " + simulator + " --slurm-tasks 2 --slurm-poll 0.2",
                              "env FAKE_SLURM=" + fake + " PATH=" + fake + ":" + std::getenv("PATH"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("squeue does not answer about job 102 (squeue: error: slurm_load_jobs error: Unable to contact"),
            std::string::npos) << r.output;
  EXPECT_EQ(read_text(fake + "/submitted"), "2\n") << r.output;  // one array and one merge job: submitted once
  EXPECT_TRUE(r.output.find("published ") != std::string::npos || r.output.find("kept aside ") != std::string::npos) << r.output;
  EXPECT_NE(run("learn status " + path("learner")).output.find("round 1: done"), std::string::npos);
}

// Regression (issue 30): default thread counts came from std::thread::hardware_concurrency(), the
// machine's CPUs: under `taskset -c 0` with OMP_NUM_THREADS=1 on 2 cores `dataset run` said "1 job(s)
// x 2 thread(s)" and `serve` "2 evaluation threads". Both now follow the CPU affinity mask, and
// OMP_NUM_THREADS when that is smaller.
TEST_F(Cli, DefaultThreadCountsFollowTheCpuAffinityAndOmpNumThreads) {
  const std::string cpu = std::to_string(first_allowed_cpu());
  ASSERT_EQ(run("dataset plan --out " + path("plan.h5") + " --samples 1" + kTinyScene).exit_code, 0);
  std::filesystem::create_directories(path("models"));
  ASSERT_EQ(run("law coulomb --mu 0.3 --out " + path("models/law.h5")).exit_code, 0);
  const std::vector<std::vector<std::string>> launchers = {{"taskset", "-c", cpu, "env", "-u", "OMP_NUM_THREADS"},
                                                           {"taskset", "-c", cpu, "env", "OMP_NUM_THREADS=1"},
                                                           {"env", "OMP_NUM_THREADS=1"}};
  for (size_t i = 0; i < launchers.size(); ++i) {
    std::string launcher;
    for (const std::string& word : launchers[i]) launcher += word + " ";
    // Shard 1/2 of a one-row plan is empty: the run says its thread counts and ends.
    const CommandResult r = run("dataset run --plan " + path("plan.h5") + " --db " + path("db.h5") + " --shard 1/2", launcher);
    EXPECT_EQ(r.exit_code, 0) << launcher << ": " << r.output;
    EXPECT_NE(r.output.find("1 job x 1 thread"), std::string::npos) << launcher << ": " << r.output;
    const std::string log = path("serve" + std::to_string(i) + ".log");
    ServeProcess server(path("models"), log, path("address" + std::to_string(i)), launchers[i]);
    ASSERT_FALSE(server.address().empty()) << launcher << ": server did not start: " << read_text(log);
    EXPECT_EQ(server.stop(), 0);
    EXPECT_NE(read_text(log).find(", 1 evaluation thread)"), std::string::npos) << launcher << ": " << read_text(log);
  }
}

}  // namespace
