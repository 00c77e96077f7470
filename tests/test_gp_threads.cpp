// The GP called from a meso code's own threads: the same answers as from one thread, and no thread
// team of its own started inside the caller's parallel region.
#include <gtest/gtest.h>
#include <omp.h>

#include <fstream>
#include <string>

#include "gp_test_data.hpp"
#include "surrogate/gp/gaussian_process.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric {
namespace {

GaussianProcess shared_gp() { return test::fixed_hyper_gp(400, 4, 2.0, {0.5, 0.5, 0.5}, 1e-4); }

// Threads of this process right now (Linux: the "Threads:" line of /proc/self/status).
int process_threads() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  }
  return -1;
}

TEST(GpThreads, InsideAParallelRegionOneEvaluationUsesItsCallingThreadOnly) {
  EXPECT_EQ(evaluation_team_size(), omp_get_max_threads());
  EXPECT_EQ(evaluation_team_size(1), 1);
  int inside[2] = {-1, -1};
#pragma omp parallel num_threads(2)
  inside[omp_get_thread_num()] = evaluation_team_size();
  EXPECT_EQ(inside[0], 1);
  EXPECT_EQ(inside[1], 1);
  // A team of one is not an active region: the cores are the evaluation's, as OpenMP would allow.
  int alone = -1, allowed = -2;
#pragma omp parallel num_threads(1)
  {
    alone = evaluation_team_size();
    allowed = omp_get_max_threads();
  }
  EXPECT_EQ(alone, allowed);
}

// Two OpenMP threads of the caller evaluate large blocks (each big enough to be split over a team)
// at once, nested parallelism switched on as a hybrid meso code may have it: the answers are those
// of one thread to the last bit, and the process never holds more threads than the caller's team.
TEST(GpThreads, TwoCallerThreadsAtOnceGetTheSerialAnswersAndStartNoTeam) {
  const GaussianProcess gp = shared_gp();
  const TrainingSet queries = test::smooth_training_set(2000, 9);
  const EvaluationRequest what{.std = true, .ci_level = 0.95};
  const Evaluation serial = gp.evaluate(queries.x, {.std = true, .ci_level = 0.95, .max_threads = 1});

  const int levels_before = omp_get_max_active_levels();
  const int team_before = omp_get_max_threads();
  omp_set_max_active_levels(2);
  omp_set_num_threads(2);  // whatever OMP_NUM_THREADS says, a nested team would be seen
  int caller_team_alone = 0;  // threads of the process while the caller's team of two runs
#pragma omp parallel num_threads(2)
  {
#pragma omp barrier
#pragma omp critical
    caller_team_alone = std::max(caller_team_alone, process_threads());
  }
  Evaluation each[2];
  int most_threads[2] = {0, 0};
#pragma omp parallel num_threads(2)
  {
    const int t = omp_get_thread_num();
    for (int repeat = 0; repeat < 3; ++repeat) {
      each[t] = gp.evaluate(queries.x, what);
      most_threads[t] = std::max(most_threads[t], process_threads());
    }
  }
  omp_set_max_active_levels(levels_before);
  omp_set_num_threads(team_before);

  // No more threads than while the caller's team ran alone: no team of the GP's own.
  for (const int most : most_threads) EXPECT_LE(most, caller_team_alone) << "a nested team was started";
  for (const Evaluation& e : each) {
    for (Eigen::Index q = 0; q < queries.x.rows(); ++q) {
      ASSERT_EQ(e.mu(q), serial.mu(q)) << q;
      ASSERT_EQ(e.std(q), serial.std(q)) << q;
      ASSERT_EQ(e.hi(q), serial.hi(q)) << q;
    }
  }
}

}  // namespace
}  // namespace mufric
