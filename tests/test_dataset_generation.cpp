// Dataset generation from a plan: every plan row answered once, resumable, sharded, merged; the
// evaluator here is a closed-form function so the bookkeeping is checked against exact values.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <random>
#include <set>
#include <thread>

#include "campaign/campaign_summary.hpp"
#include "campaign/dataset_generation.hpp"
#include "campaign/refine.hpp"
#include "common/error.hpp"
#include "common/work_pool.hpp"
#include "temp_path.hpp"

namespace mufric {
namespace {

// The one work pool (a measurement's draws, a campaign's samples): every index once, whatever the
// number of workers, and none taken after the work says stop.
TEST(WorkPool, EveryIndexRunsOnceWhateverTheWorkers) {
  for (int workers : {1, 2, 5}) {
    for (size_t count : {size_t{0}, size_t{1}, size_t{7}, size_t{200}}) {
      std::vector<std::atomic<int>> runs(count);
      run_work_pool(count, workers, [&](size_t k) {
        ++runs[k];
        return true;
      });
      for (size_t k = 0; k < count; ++k) EXPECT_EQ(runs[k].load(), 1) << workers << " workers, " << count << " jobs, job " << k;
    }
  }
}

TEST(WorkPool, FalseStopsTheTakingOfIndices) {
  std::vector<size_t> ran;
  run_work_pool(100, 1, [&](size_t k) {
    ran.push_back(k);
    return k != 3;
  });
  EXPECT_EQ(ran, (std::vector<size_t>{0, 1, 2, 3}));
  std::atomic<int> taken{0};
  run_work_pool(1000, 3, [&](size_t k) {
    ++taken;
    if (k != 10) std::this_thread::sleep_for(std::chrono::microseconds(200));
    return k != 10;
  });
  EXPECT_GE(taken.load(), 11);
  EXPECT_LT(taken.load(), 100);  // the others stop after the job they hold
}

using test::temp_path;

Dataset small_plan(Eigen::Index rows, const std::string& scene = "{\"scene\": 1}") {
  Dataset p;
  p.inputs = default_friction_box();
  p.plan.resize(rows, 3);
  for (Eigen::Index i = 0; i < rows; ++i) {
    p.plan.row(i) << 300e6 + 10e6 * static_cast<double>(i), 1.0 + 0.01 * static_cast<double>(i), 400.0 + static_cast<double>(i);
  }
  p.plan_design = "test";
  p.scene_json = scene;
  p.source = "test plan";
  return p;
}

double exact_mu(const Eigen::VectorXd& x) { return 0.1 + 1e-10 * x(0) + 0.01 * x(1) + 1e-5 * x(2); }

// Four draws of exact_mu with normal scatter of the given standard deviation, seeded by the row's
// own surfaces (independent draws: the same row gives the same draws).
SampleEvaluator four_noisy_draws(double scatter) {
  return [scatter](const SampleRequest& r) {
    SampleOutcome o;
    o.converged = true;
    std::mt19937_64 rng(r.seeds->tool ^ (r.seeds->chip << 1));
    std::normal_distribution<double> normal(0.0, scatter);
    for (int k = 0; k < 4; ++k) o.draw_mu.push_back(exact_mu(r.x) + normal(rng));
    o.mu = (o.draw_mu[0] + o.draw_mu[1] + o.draw_mu[2] + o.draw_mu[3]) / 4.0;
    return o;
  };
}

// Converges everywhere except at plan rows whose pressure ends in 30 MPa steps (rows 3, 6, ...).
SampleOutcome fake(const SampleRequest& request) {
  const Eigen::VectorXd& x = request.x;
  SampleOutcome o;
  const auto row = static_cast<long long>(std::lround((x(0) - 300e6) / 10e6));
  if (row % 3 == 0 && row > 0) {
    o.failure_reason = "did not converge at row " + std::to_string(row);
    o.diagnostics["newton_iterations"] = 30;
    return o;
  }
  o.converged = true;
  o.mu = exact_mu(x);
  o.diagnostics["newton_iterations"] = 5;
  o.diagnostics["contact_area_fraction"] = 0.5;
  return o;
}

void expect_each_row_once(const Dataset& d, long long rows) {
  std::set<long long> seen;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    const long long row = d.plan_index[static_cast<size_t>(i)];
    EXPECT_TRUE(seen.insert(row).second) << "plan row " << row << " twice";
    EXPECT_EQ(d.x.row(i), d.plan.row(row));
    if (d.converged(i)) {
      EXPECT_DOUBLE_EQ(d.mu(i), exact_mu(d.x.row(i).transpose()));
    } else {
      EXPECT_NE(d.failure_reason[static_cast<size_t>(i)].find("did not converge"), std::string::npos);
      EXPECT_TRUE(std::isnan(d.mu(i)));
    }
  }
  EXPECT_EQ(static_cast<long long>(seen.size()), rows);
}

TEST(DatasetGeneration, EveryPlanRowIsAnsweredOnceWithFailuresKept) {
  const Dataset plan = small_plan(10);
  const std::string db = temp_path("all.h5");
  std::filesystem::remove(db);
  GenerationOptions options;
  options.jobs = 3;
  const GenerationReport r = generate_dataset(plan, db, fake, options);
  EXPECT_EQ(r.ran, 10);
  EXPECT_EQ(r.failed, 3);  // rows 3, 6, 9
  const Dataset d = read_dataset(db);
  expect_each_row_once(d, 10);
  EXPECT_EQ(d.scene_json, plan.scene_json);
  ASSERT_TRUE(d.diagnostics.count("wall_seconds"));
  ASSERT_TRUE(d.diagnostics.count("contact_area_fraction"));
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    const bool failed = d.status[static_cast<size_t>(i)] != 0;
    EXPECT_EQ(std::isnan(d.diagnostics.at("contact_area_fraction")(i)), failed);  // missing on failed samples
  }
  // Training uses the converged ones only.
  EXPECT_EQ(training_set(d, db).x.rows(), 7);
}

TEST(DatasetGeneration, AnInterruptedRunResumesWhereItStopped) {
  const Dataset plan = small_plan(9);
  const std::string db = temp_path("resume.h5");
  std::filesystem::remove(db);
  std::atomic<int> calls{0};
  const SampleEvaluator counting = [&](const SampleRequest& x) {
    ++calls;
    return fake(x);
  };
  GenerationOptions first;
  first.limit = 4;  // as if killed after four samples
  EXPECT_EQ(generate_dataset(plan, db, counting, first).ran, 4);
  EXPECT_EQ(read_dataset(db).size(), 4);
  calls = 0;
  const GenerationReport second = generate_dataset(plan, db, counting, GenerationOptions{});
  EXPECT_EQ(second.already_done, 4);
  EXPECT_EQ(second.ran, 5);
  EXPECT_EQ(calls.load(), 5);
  expect_each_row_once(read_dataset(db), 9);
  // Nothing left: a third run evaluates nothing; with retry_failed the failed rows run again.
  calls = 0;
  EXPECT_EQ(generate_dataset(plan, db, counting, GenerationOptions{}).ran, 0);
  GenerationOptions retry;
  retry.retry_failed = true;
  EXPECT_EQ(generate_dataset(plan, db, counting, retry).ran, 2);  // rows 3 and 6
  EXPECT_EQ(calls.load(), 2);
  expect_each_row_once(read_dataset(db), 9);
}

TEST(DatasetGeneration, AnEvaluatorExceptionIsAFailedSampleNotACrash) {
  const Dataset plan = small_plan(3);
  const std::string db = temp_path("throws.h5");
  std::filesystem::remove(db);
  const SampleEvaluator throwing = [](const SampleRequest&) -> SampleOutcome { throw Error("scene exploded"); };
  EXPECT_EQ(generate_dataset(plan, db, throwing, GenerationOptions{}).failed, 3);
  const Dataset d = read_dataset(db);
  EXPECT_EQ(d.failure_reason[0], "exception: scene exploded");
}

TEST(DatasetGeneration, ADatabaseOfAnotherPlanOrSceneIsRefused) {
  const std::string db = temp_path("other.h5");
  std::filesystem::remove(db);
  generate_dataset(small_plan(4), db, fake, GenerationOptions{});
  try {
    generate_dataset(small_plan(5), db, fake, GenerationOptions{});
    ADD_FAILURE() << "a different plan was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("different plan"), std::string::npos) << e.what();
  }
  try {
    generate_dataset(small_plan(4, "{\"scene\": 2}"), db, fake, GenerationOptions{});
    ADD_FAILURE() << "a different scene was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("different scene"), std::string::npos) << e.what();
  }
}

TEST(DatasetGeneration, ShardsPartitionThePlanAndMergeBackWithoutDuplicates) {
  const Dataset plan = small_plan(11);
  std::vector<std::string> shards;
  for (int i = 0; i < 3; ++i) {
    shards.push_back(temp_path("shard" + std::to_string(i) + ".h5"));
    std::filesystem::remove(shards.back());
    GenerationOptions o;
    o.shard = parse_shard(std::to_string(i) + "/3");
    const GenerationReport r = generate_dataset(plan, shards.back(), fake, o);
    EXPECT_EQ(r.planned, i < 2 ? 4 : 3);  // rows i, i+3, i+6, i+9
  }
  MergeReport report;
  std::vector<std::string> with_duplicate = shards;
  with_duplicate.push_back(shards[1]);
  const Dataset merged = merge_datasets(with_duplicate, false, report);
  expect_each_row_once(merged, 11);
  EXPECT_EQ(report.files, 4);
  EXPECT_EQ(report.duplicates_removed, 4);
  EXPECT_EQ(report.plan_rows_missing, 0);
  EXPECT_EQ(report.failed, 3);
  // Only the first two shards: the rows of the third are reported missing.
  const Dataset partial = merge_datasets({shards[0], shards[1]}, false, report);
  EXPECT_EQ(report.plan_rows_missing, 3);
  EXPECT_EQ(partial.size(), 8);
}

TEST(DatasetGeneration, MergeRefusesMixedScenesUnlessAsked) {
  const std::string a = temp_path("scene_a.h5"), b = temp_path("scene_b.h5");
  std::filesystem::remove(a);
  std::filesystem::remove(b);
  GenerationOptions first, second;
  first.shard = parse_shard("0/2");
  second.shard = parse_shard("1/2");
  generate_dataset(small_plan(4, "{\"a\": 1}"), a, fake, first);
  generate_dataset(small_plan(4, "{\"b\": 1}"), b, fake, second);
  MergeReport report;
  EXPECT_THROW(merge_datasets({a, b}, false, report), Error);
  EXPECT_EQ(merge_datasets({a, b}, true, report).size(), 4);
}

// Regression (issue 30): merge said "inputs or box differ" without saying which; now it names the
// file, the input and both versions of it (name, unit, lo..hi).
TEST(DatasetGeneration, MergeNamesTheInputWhoseBoxDiffers) {
  const std::string a = temp_path("box_a.h5"), b = temp_path("box_b.h5");
  std::filesystem::remove(a);
  generate_dataset(small_plan(4), a, fake, GenerationOptions{});
  Dataset other = read_dataset(a);
  other.inputs[2].hi = 800.0 + 273.15;
  write_dataset(b, other);
  MergeReport report;
  try {
    merge_datasets({a, b}, false, report);
    ADD_FAILURE() << "a different box was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "merge: " + b + ": inputs or box differ from " + a +
                                         "'s: input 3 differs: temperature [K] 298.15..1073.15 (25°C..800°C) in " + b +
                                         ", temperature [K] 298.15..1173.15 (25°C..900°C) in " + a);
  }
  // A different unit or name is named the same way; a different number of inputs lists both.
  InputSpace renamed = default_friction_box(), fewer = default_friction_box();
  renamed[0].name = "pressure";
  renamed[0].unit = "bar";
  EXPECT_EQ(input_space_difference(renamed, "x.h5", default_friction_box(), "y.h5"),
            "input 1 differs: pressure [bar] 300000000..1300000000 in x.h5, contact_pressure [Pa] "
            "300000000..1300000000 (300MPa..1300MPa) in y.h5");
  fewer.pop_back();
  EXPECT_EQ(input_space_difference(fewer, "x.h5", default_friction_box(), "y.h5"),
            "x.h5 has 2 inputs (contact_pressure, sliding_velocity), y.h5 has 3 (contact_pressure, sliding_velocity, "
            "temperature)");
  fewer.pop_back();
  EXPECT_EQ(input_space_difference(fewer, "x.h5", default_friction_box(), "y.h5"),
            "x.h5 has 1 input (contact_pressure), y.h5 has 3 (contact_pressure, sliding_velocity, temperature)");
  EXPECT_EQ(input_space_difference(default_friction_box(), "x.h5", default_friction_box(), "y.h5"), "");
}

TEST(DatasetGeneration, ShardTextIsChecked) {
  EXPECT_EQ(parse_shard("2/5").index, 2);
  EXPECT_EQ(parse_shard("2/5").count, 5);
  for (const char* bad : {"5/5", "-1/3", "1", "a/b", "1/0", "1/2x"}) EXPECT_THROW(parse_shard(bad), Error) << bad;
}

// Independent draws (issue 33): every plan row gets its own seeds, derived from the plan's seed and
// the row alone, so that the same plan gives the same seeds (and, the evaluator being deterministic,
// the same μ bit for bit) whatever the shards, jobs or order; rows never share them.
TEST(DatasetGeneration, IndependentDrawsGiveEachRowItsOwnReproducibleSeeds) {
  std::set<std::uint64_t> tools, chips;
  constexpr long long kRows = 10000;
  for (long long row = 0; row < kRows; ++row) {
    const DrawSeeds s = row_draw_seeds(7, row);
    EXPECT_LT(s.tool, std::uint64_t{1} << 30);
    EXPECT_LT(s.chip, std::uint64_t{1} << 30);
    tools.insert(s.tool);
    chips.insert(s.chip);
    const DrawSeeds again = row_draw_seeds(7, row);
    ASSERT_EQ(again.tool, s.tool);
    ASSERT_EQ(again.chip, s.chip);
  }
  // Distinct between rows (10 000 draws from 2^30 values collide with probability ~5 %: allow one).
  EXPECT_GE(tools.size(), static_cast<size_t>(kRows - 1));
  EXPECT_GE(chips.size(), static_cast<size_t>(kRows - 1));
  EXPECT_NE(row_draw_seeds(8, 0).tool, row_draw_seeds(7, 0).tool);  // another plan, other surfaces

  Dataset plan = small_plan(6);
  plan.draws = DrawDesign::independent;
  plan.plan_seed = 7;
  // A deterministic stand-in for the micro-model: each draw's μ a function of the point and its seeds.
  const SampleEvaluator seeded = [](const SampleRequest& r) {
    SampleOutcome o;
    EXPECT_TRUE(r.seeds.has_value());
    o.converged = true;
    for (std::uint64_t k = 0; k < 3; ++k) {
      o.draw_mu.push_back(exact_mu(r.x) + 1e-12 * static_cast<double>((r.seeds->tool + k) % 1000) +
                          1e-9 * static_cast<double>((r.seeds->chip + k) % 1000));
    }
    o.mu = (o.draw_mu[0] + o.draw_mu[1] + o.draw_mu[2]) / 3.0;
    return o;
  };
  const std::string whole = temp_path("independent.h5"), half0 = temp_path("independent0.h5"),
                    half1 = temp_path("independent1.h5");
  for (const auto& f : {whole, half0, half1}) std::filesystem::remove(f);
  GenerationOptions two_jobs;
  two_jobs.jobs = 2;
  generate_dataset(plan, whole, seeded, two_jobs);
  GenerationOptions shard;
  shard.shard = {0, 2};
  generate_dataset(plan, half0, seeded, shard);
  shard.shard = {1, 2};
  generate_dataset(plan, half1, seeded, shard);
  MergeReport report;
  const Dataset merged = merge_datasets({half1, half0}, false, report);
  const Dataset d = read_dataset(whole);
  EXPECT_EQ(d.draws, DrawDesign::independent);
  ASSERT_EQ(d.draw_mu.cols(), 3);
  for (const Dataset* db : {&d, &merged}) {
    for (Eigen::Index i = 0; i < db->size(); ++i) {
      const long long row = db->plan_index[static_cast<size_t>(i)];
      const DrawSeeds s = row_draw_seeds(7, row);
      EXPECT_EQ(db->tool_seed[static_cast<size_t>(i)], static_cast<long long>(s.tool));
      EXPECT_EQ(db->chip_seed[static_cast<size_t>(i)], static_cast<long long>(s.chip));
      SampleRequest again{plan.plan.row(row).transpose(), row, s};
      const SampleOutcome o = seeded(again);
      for (Eigen::Index k = 0; k < 3; ++k) EXPECT_EQ(db->draw_mu(i, k), o.draw_mu[static_cast<size_t>(k)]);
      EXPECT_EQ(db->mu(i), o.mu);
    }
  }
  // A database of the same plan points drawn in common is another database.
  Dataset common = plan;
  common.draws = DrawDesign::common;
  try {
    generate_dataset(common, whole, seeded, {});
    ADD_FAILURE() << "a database of independent draws was resumed with a plan of common ones";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("draws its roughness differently"), std::string::npos) << e.what();
  }
  // With common draws the evaluator gets no seeds, and the samples record the scene's own (-1).
  const std::string shared = temp_path("common.h5");
  std::filesystem::remove(shared);
  generate_dataset(common, shared, [](const SampleRequest& r) {
    EXPECT_FALSE(r.seeds.has_value());
    return fake(r);
  }, {});
  const Dataset c = read_dataset(shared);
  EXPECT_EQ(c.draws, DrawDesign::common);
  for (long long seed : c.tool_seed) EXPECT_EQ(seed, -1);
  EXPECT_EQ(c.draw_mu.cols(), 0);
}

// What a model says of its training data: source and code, plan, draws, mesh, outcomes, time.
TEST(DatasetGeneration, TheCampaignSummarySaysPlanDrawsMeshOutcomesAndTime) {
  Dataset plan = small_plan(6, R"({"discretisation": {"degree": 2, "elements_x": 64, "elements_y": 12}})");
  plan.draws = DrawDesign::independent;
  plan.plan_seed = 3;
  plan.plan_design = "sobol";
  const std::string db = temp_path("summary.h5");
  std::filesystem::remove(db);
  generate_dataset(plan, db, [](const SampleRequest& r) {
    SampleOutcome o = fake(r);
    if (o.converged) o.draw_mu = {o.mu, o.mu, o.mu};
    return o;
  }, {});
  const Dataset d = read_dataset(db);
  const std::string s = campaign_summary(d);
  for (const std::string part : {"test plan", "plan 6 points, design sobol (seed 3)", "draws independent", "15 draws, 3 per sample",
                                 "mesh 64 x 12 of degree 2", "6 samples (5 converged, 0 outside the model, 1 failed)",
                                 "micro-model wall time"}) {
    EXPECT_NE(s.find(part), std::string::npos) << "'" << part << "' not in: " << s;
  }
  Dataset bare = d;
  bare.scene_json = "not json";
  EXPECT_EQ(campaign_summary(bare).find("mesh"), std::string::npos);
}

// A campaign that ran a prefix of its plan hands over to refine: the rows not run leave the plan, so
// the budget goes to the picks; a row not run before one that was is refused by number.
TEST(DatasetGeneration, RefineCanLeaveThePendingTailOfItsPlanOut) {
  Dataset plan = small_plan(20);
  plan.draws = DrawDesign::independent;
  plan.plan_seed = 9;
  const SampleEvaluator noisy = four_noisy_draws(0.005);
  const std::string db = temp_path("prefix.h5");
  std::filesystem::remove(db);
  GenerationOptions first;
  first.limit = 12;
  generate_dataset(plan, db, noisy, first);
  RefineOptions o;
  o.db = db;
  o.budget = 2;
  o.batch = 2;
  o.restarts = 0;
  o.drop_pending = true;
  o.make_evaluator = [&](const Dataset&) { return noisy; };
  long long dropped = -1;
  o.on_drop = [&](long long n) { dropped = n; };
  EXPECT_EQ(refine_dataset(o).spent, 2);
  EXPECT_EQ(dropped, 8);
  const Dataset d = read_dataset(db);
  EXPECT_EQ(d.plan.rows(), 14);  // the 12 run, then the two picks
  EXPECT_EQ(d.size(), 14);
  EXPECT_NE(d.plan_design.find("test prefix of 12"), std::string::npos) << d.plan_design;
  for (Eigen::Index i = 0; i < 12; ++i) EXPECT_EQ(d.plan.row(i), plan.plan.row(i));

  Dataset gap = plan;
  gap.plan_index = {0, 1, 2, 5};
  try {
    drop_pending_plan_rows(gap, "gap.h5");
    ADD_FAILURE() << "rows 3 and 4 lie before row 5, which ran";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("plan rows 3, 4 have not run"), std::string::npos) << e.what();
  }
  Dataset tail = plan;
  tail.plan_index = {0, 2, 1};
  EXPECT_EQ(drop_pending_plan_rows(tail, "tail.h5"), 17);
  EXPECT_EQ(tail.plan.rows(), 3);
}

// dataset refine on independent draws: stochastic kriging, picks by IMSE among new points and more
// draws at existing ones. With one Sobol' candidate per round, a batch of three must repeat existing
// points: each repeat is a new plan row at that row's point, run with its own seeds.
TEST(DatasetGeneration, RefineOnIndependentDrawsRepeatsPointsWithNewDraws) {
  Dataset plan = small_plan(12);
  for (Eigen::Index i = 0; i < 12; ++i) {
    plan.plan.row(i) << 300e6 + 1e9 * static_cast<double>(i % 4) / 3.0, 0.5 + 2.0 * static_cast<double>((i / 4) % 3) / 2.0, 400.0 + 40.0 * static_cast<double>(i % 3);
  }
  plan.draws = DrawDesign::independent;
  plan.plan_seed = 5;
  const std::string db = temp_path("refine.h5");
  std::filesystem::remove(db);
  // Four draws whose scatter (0.02) dwarfs the trend: repeats are worth as much as new points.
  const SampleEvaluator noisy = four_noisy_draws(0.02);
  generate_dataset(plan, db, noisy, {});
  RefineOptions o;
  o.db = db;
  o.budget = 3;
  o.batch = 3;
  o.restarts = 0;
  o.candidate_count = 1;
  o.make_evaluator = [&](const Dataset&) { return noisy; };
  std::vector<RefinePick> picks;
  o.on_pick = [&](const RefinePick& p) { picks.push_back(p); };
  EXPECT_EQ(refine_dataset(o).spent, 3);
  ASSERT_EQ(picks.size(), 3u);
  const Dataset d = read_dataset(db);
  long long repeats = 0;
  for (const RefinePick& p : picks) {
    EXPECT_GT(p.imse_reduction, 0.0);
    if (p.replicates_row < 0) continue;
    ++repeats;
    EXPECT_EQ(d.plan.row(p.plan_row), d.plan.row(p.replicates_row));
    const DrawSeeds original = row_draw_seeds(5, p.replicates_row), repeat = row_draw_seeds(5, p.plan_row);
    EXPECT_NE(original.tool, repeat.tool);
    EXPECT_NE(original.chip, repeat.chip);
  }
  EXPECT_GE(repeats, 2);  // at most one new point was on offer
  EXPECT_EQ(d.size(), 15);
  EXPECT_EQ(d.draws, DrawDesign::independent);
}

// A run that completes with a warning (a molten chip) is kept with its μ and standard error, as
// outside the model: training leaves it out, --retry-failed does not rerun it, merging keeps it so.
TEST(DatasetGeneration, SamplesOutsideTheModelAreKeptFlaggedAndNeverTrainedOn) {
  const Dataset plan = small_plan(4);
  const std::string db = temp_path("molten.h5");
  std::filesystem::remove(db);
  std::atomic<int> calls{0};
  const auto molten_last = [&](const SampleRequest& request) {
    const Eigen::VectorXd& x = request.x;
    ++calls;
    SampleOutcome o;
    o.converged = true;
    o.mu = exact_mu(x);
    o.mu_std = 0.01 * o.mu;
    if (x(0) > 325e6) o.warnings = {"the chip reached its melting temperature (1500 C)"};
    return o;
  };
  generate_dataset(plan, db, molten_last, {});
  const Dataset d = read_dataset(db);
  ASSERT_EQ(d.size(), 4);
  for (Eigen::Index i = 0; i < 4; ++i) {
    const bool molten = d.x(i, 0) > 325e6;
    EXPECT_EQ(d.outside_model(i), molten) << i;
    EXPECT_DOUBLE_EQ(d.mu(i), exact_mu(d.x.row(i).transpose()));  // kept, for inspection
    EXPECT_DOUBLE_EQ(d.mu_std(i), 0.01 * d.mu(i));
    if (molten) {
      EXPECT_NE(d.failure_reason[static_cast<size_t>(i)].find("melting"), std::string::npos);
    }
  }
  const TrainingSet t = training_set(d, db);
  EXPECT_EQ(t.x.rows(), 3);
  EXPECT_EQ(t.outside_model, 1);
  GenerationOptions retry;
  retry.retry_failed = true;
  const int before = calls;
  generate_dataset(plan, db, molten_last, retry);
  EXPECT_EQ(calls, before);  // nothing failed, so nothing reran
  MergeReport report;
  const Dataset merged = merge_datasets({db}, false, report);
  EXPECT_EQ(report.converged + report.failed, 4);
  long long outside = 0;
  for (Eigen::Index i = 0; i < merged.size(); ++i) outside += merged.outside_model(i);
  EXPECT_EQ(outside, 1);
  EXPECT_EQ(merged.mu_std, d.mu_std);
}

}  // namespace
}  // namespace mufric
