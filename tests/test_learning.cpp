// The on-line learner (campaign/learning.hpp, issue 62): its gate's decisions on small synthetic
// models, and whole rounds on a closed-form "micro-model": the server's log read from where it
// stopped, the box grown toward it, the round run and published atomically, a version rolled back,
// the loop resting when the log is quiet and stopping at its budget, and a round resumed after a stop.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "campaign/dataset_generation.hpp"
#include "campaign/learning.hpp"
#include "campaign/refine.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "surrogate/calibration/calibration.hpp"
#include "surrogate/calibration/calibration_workflow.hpp"
#include "surrogate/models/model_file.hpp"
#include "surrogate/core/sampling.hpp"
#include "temp_path.hpp"

namespace mufric {
namespace {

namespace fs = std::filesystem;

// A smooth μ(p, v, T) standing in for the micro-model; `offset` makes a "damaged" one (runs made
// with another scene).
double smooth_mu(const Eigen::VectorXd& x, double offset = 0.0) {
  return 0.2 + 0.05 * std::sin(3e-9 * x(0)) + 0.01 * x(1) + 1e-4 * (x(2) - 400.0) + offset;
}
SampleEvaluator smooth_evaluator(double offset = 0.0) {
  return [offset](const SampleRequest& r) {
    SampleOutcome o;
    o.converged = true;
    o.mu = smooth_mu(r.x, offset);
    o.diagnostics["micro_wall_seconds"] = 10.0;
    return o;
  };
}

TrainingSet points_of(const InputSpace& box, const Eigen::MatrixXd& x, Eigen::Index offset_from_row, double offset) {
  TrainingSet t;
  t.inputs = box;
  t.x = x;
  t.mu.resize(x.rows());
  t.mu_std = Eigen::VectorXd::Constant(x.rows(), std::nan(""));
  for (Eigen::Index i = 0; i < x.rows(); ++i) t.mu(i) = smooth_mu(x.row(i).transpose(), i >= offset_from_row ? offset : 0.0);
  return t;
}

GaussianProcess fit(const TrainingSet& t) {
  GpTrainingOptions o;
  o.restarts = 0;
  return train_gaussian_process(t, o);
}

// The gate publishes a candidate that learned new points of the same μ, and keeps aside one whose new
// points disagree with what the served version knew, or that lost its points.
TEST(Learning, TheGatePassesMoreOfTheSameAndRefusesADamagedRound) {
  const InputSpace box = default_friction_box();
  const Eigen::MatrixXd old_x = plan_in_box(PlanDesign::sobol, 24, box, 3);
  const Eigen::MatrixXd new_x = plan_in_box(PlanDesign::sobol, 12, box, 11);  // interleaved with the old points
  Eigen::MatrixXd all_x(36, 3);
  all_x << old_x, new_x;
  const GaussianProcess served = fit(points_of(box, old_x, 0, 0.0));
  const FastEvaluatorOptions tolerances;
  const GateDecision good = gate_candidate(served, fit(points_of(box, all_x, 24, 0.0)), tolerances);
  EXPECT_TRUE(good.publish) << good.reason;
  EXPECT_EQ(good.old_points, 24);
  EXPECT_EQ(good.new_points, 12);
  EXPECT_LE(good.candidate_loo_rmse, good.allowed_loo_rmse);
  const GateDecision damaged = gate_candidate(served, fit(points_of(box, all_x, 24, 0.03)), tolerances);
  EXPECT_FALSE(damaged.publish) << damaged.reason;
  EXPECT_GT(damaged.candidate_loo_rmse, damaged.allowed_loo_rmse) << damaged.reason;
  const GateDecision other = gate_candidate(served, fit(points_of(box, new_x, 0, 0.0)), tolerances);
  EXPECT_FALSE(other.publish);
  EXPECT_NE(other.reason.find("another database"), std::string::npos) << other.reason;
}

// The coverage test's tail against the sum of its terms written out: P(X ≤ 5 | 8, 0.95).
// A state whose round stands at a step no learner has is refused, naming the file and the word (it
// would otherwise resume at some step silently); the steps' own words read back as written.
TEST(Learning, AStateWithAnUnknownStepIsAnErrorNamingTheFileAndTheWord) {
  const std::string dir = test::temp_path("unknown-step-learner");
  fs::create_directories(dir);
  LearnState s;
  s.rounds.push_back(LearnRound{.number = 1, .step = LearnStep::gate});
  write_learn_state(dir, s);
  EXPECT_EQ(read_learn_state(dir).rounds.at(0).step, LearnStep::gate);
  std::string text = *read_whole_file(learn_state_path(dir));
  const std::string recorded = "\"step\": \"gate\"";
  const auto at = text.find(recorded);
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, recorded.size(), "\"step\": \"walk\"");
  write_file_atomically(learn_state_path(dir), text);
  try {
    read_learn_state(dir);
    FAIL() << "an unknown step was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("learn.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'walk'"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(Learning, TheBinomialTailIsTheSumOfItsTerms) {
  const double p = 0.95, q = 0.05;
  const double by_hand = std::pow(q, 8) + 8 * p * std::pow(q, 7) + 28 * p * p * std::pow(q, 6) + 56 * std::pow(p, 3) * std::pow(q, 5) +
                         70 * std::pow(p, 4) * std::pow(q, 4) + 56 * std::pow(p, 5) * std::pow(q, 3);
  EXPECT_NEAR(binomial_lower_tail(5, 8, p), by_hand, 1e-15);
  EXPECT_EQ(binomial_lower_tail(8, 8, p), 1.0);
  EXPECT_EQ(binomial_lower_tail(-1, 8, p), 0.0);
}

// Where the learner's picks go on a campaign of independent draws (stochastic kriging, picks by the
// variance they remove): averaged over the logged rows, all at 300-330 MPa, the picks move toward
// those pressures; averaged over the box, they spread over it.
TEST(Learning, PicksRemoveVarianceWhereTheQueriesAre) {
  Dataset db;
  db.inputs = default_friction_box();
  db.plan = plan_in_box(PlanDesign::sobol, 24, db.inputs, 7);
  db.plan_design = "sobol";
  db.draws = DrawDesign::independent;
  db.plan_seed = 3;
  db.scene_json = "{}";
  const std::string path = test::temp_path("picks-db.h5");
  fs::remove(path);
  generate_dataset(db, path, [](const SampleRequest& r) {
    SampleOutcome o;
    o.converged = true;
    std::mt19937_64 rng(r.seeds->tool);
    std::normal_distribution<double> scatter(0.0, 0.01);
    for (int k = 0; k < 4; ++k) o.draw_mu.push_back(smooth_mu(r.x) + scatter(rng));
    o.mu = (o.draw_mu[0] + o.draw_mu[1] + o.draw_mu[2] + o.draw_mu[3]) / 4.0;
    return o;
  }, {});
  const Dataset run = read_dataset(path);
  const TrainingSet data = training_set(run, path);
  GpTrainingOptions training;
  training.restarts = 0;
  const GaussianProcess gp = fit_campaign_gp(data, training);
  ASSERT_TRUE(gp.has_patch_scatter());
  Eigen::MatrixXd logged = plan_in_box(PlanDesign::sobol, 64, {{"contact_pressure", "Pa", 300e6, 330e6}, db.inputs[1], db.inputs[2]}, 9);
  const auto mean_pressure_of_picks = [&](bool from_logged) {
    Dataset copy = run;
    PickOptions o;
    o.reference_from_logged = from_logged;
    double sum = 0.0;
    const auto picks = append_refinement_picks(copy, gp, data, logged, o, 1, 4);
    for (const RefinePick& p : picks) sum += copy.plan(p.plan_row, 0);
    return sum / static_cast<double>(picks.size());
  };
  const double near = mean_pressure_of_picks(true), spread = mean_pressure_of_picks(false);
  EXPECT_LT(near, 500e6) << near;
  EXPECT_LT(near, spread - 100e6) << near << " " << spread;
}

// A learner's scratch files (its directory, the served folder, the campaign database, the server's
// log of the served model NAME), emptied; a campaign run there on a closed form, and its GP.
struct LearnerScratch {
  std::string dir, folder, db, log, name;
  LearnerScratch(const std::string& prefix, const std::string& model_name)
      : dir(test::temp_path(prefix + "learner")),
        folder(test::temp_path(prefix + "served")),
        db(test::temp_path(prefix + "learn-db.h5")),
        log(test::temp_path(prefix + "uncertain") + "/" + model_name + ".csv"),
        name(model_name) {
    for (const auto& d : {dir, folder, fs::path(log).parent_path().string()}) fs::remove_all(d);
    fs::remove(db);
    fs::create_directories(folder);
    fs::create_directories(fs::path(log).parent_path());
  }
  std::string served() const { return folder + "/" + name + ".h5"; }
  // `rows` Sobol' plan rows over `box` run on `evaluate` into db; their GP, fitted without restarts.
  GaussianProcess run_campaign(const InputSpace& box, Eigen::Index rows, const std::string& scene, const SampleEvaluator& evaluate) const {
    Dataset plan;
    plan.inputs = box;
    plan.plan = plan_in_box(PlanDesign::sobol, rows, plan.inputs, 5);
    plan.plan_design = "sobol";
    plan.scene_json = "{\"scene\": \"" + scene + "\"}";
    plan.source = "learner test";
    generate_dataset(plan, db, evaluate, {});
    GpTrainingOptions o;
    o.restarts = 0;
    return fit_campaign_gp(training_set(read_dataset(db), db), o);
  }
  LearnRunOptions run(SampleEvaluator evaluate) const {
    LearnRunOptions o;
    o.make_evaluator = [evaluate](const Dataset&) { return evaluate; };
    o.fast.max_work = 1e9;  // small grids: the test is about the loop
    return o;
  }
  LearnSetup setup() const {
    LearnSetup s;
    s.db = db;
    s.served_model = served();
    s.log = log;
    s.round_samples = 4;
    s.budget_core_hours = 1.0;
    s.restarts = 0;
    return s;
  }
};

// A campaign of 20 plan rows in the default box, its served GP, and a server log of queries below
// the box's pressures, written as `serve --log-uncertain` writes it.
struct LearnerFixture : LearnerScratch {
  LearnerFixture() : LearnerScratch("", "gp") {
    save_model(served(), run_campaign(default_friction_box(), 20, "closed form", smooth_evaluator()));
    log_queries(6, 100);
  }
  // Appends `rows` queries at 150–250 MPa (below the box) and sets the query count to `queries`.
  void log_queries(int rows, long long queries) const {
    const bool fresh = !fs::exists(log);
    std::ofstream out(log, std::ios::app);
    if (fresh) out << "contact_pressure[Pa],sliding_velocity[m/s],temperature[K],ci95_width,outside_inputs\n";
    for (int i = 0; i < rows; ++i) out << 150e6 + 20e6 * i << "," << 1.0 + 0.1 * i << "," << 500.0 + 10 * i << ",0.2,1\n";
    out.close();
    write_file_atomically(fs::path(log).replace_extension(".outside.json").string(),
                          "{\"model\": \"gp\", \"queries\": " + std::to_string(queries) + "}");
  }
};

// One round: the box grows toward the logged pressures, four runs are made there, the retrained GP
// passes the gate and replaces the served file; rolled back, the served file is the first version's
// bytes again. With no new row logged the learner rests; a spent budget stops it.
TEST(Learning, ARoundGrowsTheBoxRunsPublishesAndRollsBack) {
  const LearnerFixture f;
  learn_init(f.dir, f.setup());
  EXPECT_THROW(learn_init(f.dir, f.setup()), Error);  // one learner per directory
  const std::string first_version = file_version(f.served());
  const LearnReport report = learn_rounds(f.dir, f.run(smooth_evaluator()));
  EXPECT_EQ(report.rounds_finished, 1);
  const LearnState s = read_learn_state(f.dir);
  ASSERT_EQ(s.rounds.size(), 1u);
  const LearnRound& r = s.rounds[0];
  EXPECT_EQ(r.step, LearnStep::done);
  EXPECT_EQ(r.logged_rows, 6);
  EXPECT_DOUBLE_EQ(r.uncertain_share, 0.06);
  EXPECT_EQ(r.end_plan_row - r.first_plan_row, 4);
  EXPECT_NEAR(s.spent_core_seconds, r.run_core_seconds, 1e-12);
  const Dataset db = read_dataset(f.db);
  EXPECT_EQ(db.size(), 24);
  EXPECT_LT(db.inputs[0].lo, 300e6);  // grown toward 150 MPa
  EXPECT_EQ(db.box_history.size(), 1u);
  ASSERT_TRUE(r.gate.publish) << r.gate.reason;
  EXPECT_EQ(file_version(f.served()), r.version);
  EXPECT_NE(r.version, first_version);
  EXPECT_EQ(load_model(f.served())->inputs()[0].lo, db.inputs[0].lo);
  ASSERT_EQ(s.served.size(), 2u);
  EXPECT_EQ(s.served[0].version, first_version);

  // Nothing new in the log: the learner rests and plans nothing.
  EXPECT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).stop, LearnStop::resting);
  // A few rows among many queries: still resting (1 in 1000 is below the 1 % threshold).
  f.log_queries(1, 1100);
  EXPECT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).stop, LearnStop::resting);
  EXPECT_EQ(read_learn_state(f.dir).rounds.size(), 1u);

  learn_rollback(f.dir, first_version);
  EXPECT_EQ(file_version(f.served()), first_version);
  EXPECT_THROW(learn_rollback(f.dir, "0123456789abcdef"), Error);
}

// The server renames a full log to NAME.csv.1 and begins a new one (serve --uncertain-max-rows): the
// learner reads the rest of the renamed file, then the new one from its start, and no row twice.
TEST(Learning, ALogRenamedWhenFullIsFinishedBeforeTheNewOneIsRead) {
  const LearnerFixture f;
  learn_init(f.dir, f.setup());
  ASSERT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).rounds_finished, 1);
  EXPECT_EQ(read_learn_state(f.dir).rounds.back().logged_rows, 6);
  f.log_queries(2, 150);  // two more rows in the file the learner was reading
  fs::rename(f.log, f.log + ".1");
  f.log_queries(3, 200);  // a new file, begun with its header
  ASSERT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).rounds_finished, 1);
  EXPECT_EQ(read_learn_state(f.dir).rounds.back().logged_rows, 5);
  EXPECT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).stop, LearnStop::resting);  // all read
}

// A kill after a round's picks were written and before the state recorded them leaves plan rows no
// sample answers: the next learner adopts them as its round and runs them. The budget, counted in
// the runs' own core-seconds, bounds each round's batch and then stops the loop.
TEST(Learning, AnUnfinishedRoundIsResumedAtItsStepAndTheBudgetStopsTheLoop) {
  const LearnerFixture f;
  LearnSetup setup = f.setup();
  setup.budget_core_hours = 30.0 / 3600.0;  // three 10 s samples
  learn_init(f.dir, setup);
  // The database as such a kill leaves it: two picks in the plan, no round in the state.
  Dataset db = read_dataset(f.db);
  const Eigen::Index rows = db.plan.rows();
  db.plan.conservativeResize(rows + 2, Eigen::NoChange);
  db.plan.row(rows) = db.plan.row(0) * 1.01;
  db.plan.row(rows + 1) = db.plan.row(1) * 1.01;
  write_dataset(f.db, db);
  // Without a round recorded: the learner adopts the pending rows as its round.
  const LearnReport report = learn_rounds(f.dir, f.run(smooth_evaluator()));
  EXPECT_EQ(report.rounds_finished, 1);
  LearnState s = read_learn_state(f.dir);
  ASSERT_EQ(s.rounds.size(), 1u);
  EXPECT_EQ(s.rounds[0].first_plan_row, rows);
  EXPECT_EQ(s.rounds[0].step, LearnStep::done);
  EXPECT_EQ(read_dataset(f.db).size(), rows + 2);
  // 20 s spent of 30: the next round may still plan one run (10 s each), then the budget stops it.
  f.log_queries(6, 200);
  EXPECT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).rounds_finished, 1);
  s = read_learn_state(f.dir);
  EXPECT_EQ(s.rounds.back().end_plan_row - s.rounds.back().first_plan_row, 1);
  f.log_queries(6, 300);
  EXPECT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).stop, LearnStop::budget_spent);
}

// A round whose runs were damaged (a closed form 0.03 above the campaign's, as runs made with another
// scene but recorded as the campaign's would be) near the points the previous round ran: the gate
// refuses it for its values, the served file stays, and its samples are quarantined (failed, with the
// reason, μ kept), so that the next healthy round is judged without them and published.
TEST(Learning, ARoundRefusedForItsValuesIsQuarantinedAndTheNextRoundIsPublishedWithoutIt) {
  const LearnerFixture f;
  learn_init(f.dir, f.setup());
  ASSERT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).rounds_finished, 1);
  ASSERT_TRUE(read_learn_state(f.dir).rounds.at(0).gate.publish);
  const std::string published = file_version(f.served());
  f.log_queries(6, 200);
  ASSERT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator(0.03))).rounds_finished, 1);
  const LearnRound damaged = read_learn_state(f.dir).rounds.at(1);
  EXPECT_FALSE(damaged.gate.publish);
  EXPECT_TRUE(damaged.gate.values_refused) << damaged.gate.reason;
  EXPECT_EQ(damaged.quarantined, damaged.end_plan_row - damaged.first_plan_row);
  EXPECT_EQ(file_version(f.served()), published);
  // The round's samples in the database: failed, with the reason, their damaged values readable for
  // whoever looks into the fault; returns how many.
  const auto expect_quarantined = [&damaged](const Dataset& db) {
    long long quarantined = 0;
    for (Eigen::Index i = 0; i < db.size(); ++i) {
      const long long row = db.plan_index[static_cast<size_t>(i)];
      if (row < damaged.first_plan_row || row >= damaged.end_plan_row) continue;
      EXPECT_TRUE(db.failed(i));
      EXPECT_NE(db.failure_reason[static_cast<size_t>(i)].find("quarantined by mufric learn: round 2"), std::string::npos);
      EXPECT_NEAR(db.mu(i), smooth_mu(db.x.row(i).transpose(), 0.03), 1e-12);
      ++quarantined;
    }
    return quarantined;
  };
  EXPECT_EQ(expect_quarantined(read_dataset(f.db)), damaged.quarantined);
  f.log_queries(6, 300);
  ASSERT_EQ(learn_rounds(f.dir, f.run(smooth_evaluator())).rounds_finished, 1);
  const LearnRound healthy = read_learn_state(f.dir).rounds.at(2);
  EXPECT_TRUE(healthy.gate.publish) << healthy.gate.reason;
  EXPECT_EQ(healthy.gate.old_points, 24);
  EXPECT_EQ(healthy.gate.new_points, healthy.end_plan_row - healthy.first_plan_row);  // the quarantined ones are not among them
  EXPECT_EQ(file_version(f.served()), healthy.version);
  EXPECT_EQ(expect_quarantined(read_dataset(f.db)), damaged.quarantined);  // through the next round's rewrite too
}

// --- a calibrated served model -----------------------------------------------------------------

// A campaign over (p, v) and a law's shear factor m, run on a closed form; the model served is its GP
// calibrated on eight measurements made at m = 0.35; the server logged queries below the box's
// pressures, in the calibrated model's served conditions (p, v).
double law_mu(const Eigen::VectorXd& x) {
  const double ps = (x(0) - 300e6) / 1000e6, vs = (x(1) - 0.375) / 2.958;
  return 0.1 + 0.5 * x(2) * (1.0 - 0.3 * ps) - 0.05 * vs + 0.04 * ps * vs;
}
SampleEvaluator law_evaluator() {
  return [](const SampleRequest& r) {
    SampleOutcome o;
    o.converged = true;
    o.mu = law_mu(r.x);
    o.diagnostics["micro_wall_seconds"] = 10.0;
    return o;
  };
}

struct CalibratedLearnerFixture : LearnerScratch {
  Measurements data;
  EnsembleOptions sampler;
  explicit CalibratedLearnerFixture(int sampler_steps = 1200) : LearnerScratch("cal-", "calibrated") {
    const InputSpace box = {default_friction_box()[0], default_friction_box()[1], {"shear_factor", "1", 0.2, 0.9}};
    auto emulator = std::make_shared<const GaussianProcess>(run_campaign(box, 24, "closed form with a law", law_evaluator()));
    data.condition_names = {"contact_pressure", "sliding_velocity"};
    const Eigen::MatrixXd at = plan_in_box(PlanDesign::sobol, 8, {box[0], box[1]}, 13);
    data.conditions = at;
    data.mu.resize(at.rows());
    data.mu_sd = Eigen::VectorXd::Constant(at.rows(), 0.01);
    for (Eigen::Index i = 0; i < at.rows(); ++i) {
      data.mu(i) = law_mu(Eigen::Vector3d(at(i, 0), at(i, 1), 0.35)) + 0.005 * std::sin(7.0 * static_cast<double>(i));
      data.row_names.push_back("measured line " + std::to_string(i + 2));
    }
    sampler.walkers = 12;
    sampler.burn_in_steps = 300;
    sampler.steps = sampler_steps;
    sampler.seed = 23;
    CalibrationSetup setup;
    setup.problem = std::make_shared<const CalibrationProblem>(emulator, data, std::vector<std::string>{"shear_factor"}, CalibrationPriors{});
    setup.data_source = "measured.csv";
    save_model(served(), calibrated_model(setup, calibrate(*setup.problem, sampler)));
    std::ofstream out(log);
    out << "contact_pressure[Pa],sliding_velocity[m/s],ci95_width,outside_inputs\n";
    for (int i = 0; i < 6; ++i) out << 150e6 + 20e6 * i << "," << 1.0 + 0.1 * i << ",0.2,1\n";
    out.close();
    write_file_atomically(fs::path(log).replace_extension(".outside.json").string(), "{\"model\": \"calibrated\", \"queries\": 100}");
  }
};

// A round on a served calibrated model: the picks go to the queried pressures, at shear factors on the
// posterior's side of the box (the variance they remove is averaged over the queries at posterior
// samples of m, about 0.35; the box's middle is 0.55), the retrained GP becomes the emulator of a calibration run
// again on the served model's measurements with its priors and sampler (the same posterior, to the
// bit, as that calibration run directly on the retrained GP), and the gate publishes it, counting the
// measurements its predictive covers.
TEST(Learning, ACalibratedModelIsRecalibratedOnItsMeasurementsBeforeTheGate) {
  const CalibratedLearnerFixture f;
  learn_init(f.dir, f.setup());
  ASSERT_EQ(learn_rounds(f.dir, f.run(law_evaluator())).rounds_finished, 1);
  const LearnRound r = read_learn_state(f.dir).rounds.at(0);
  ASSERT_TRUE(r.gate.publish) << r.gate.reason;
  EXPECT_EQ(r.gate.old_points, 24);
  EXPECT_EQ(r.gate.new_points, 4);
  EXPECT_EQ(r.gate.measurements, 8);
  EXPECT_GE(r.gate.measurements_covered, 7) << r.gate.reason;
  EXPECT_NE(r.gate.reason.find("recalibrated: "), std::string::npos) << r.gate.reason;
  const Dataset db = read_dataset(f.db);
  EXPECT_LT(db.inputs[0].lo, 300e6);  // the box grew toward the queried pressures
  int at_queried_pressures = 0, below_box_middle_m = 0;
  for (long long row = r.first_plan_row; row < r.end_plan_row; ++row) {
    at_queried_pressures += db.plan(row, 0) < 300e6;
    below_box_middle_m += db.plan(row, 2) < 0.55;
  }
  EXPECT_GE(at_queried_pressures, 3);
  EXPECT_GE(below_box_middle_m, 3) << "the picks' shear factors follow the posterior (m = 0.35), not the box";

  const std::unique_ptr<FrictionModel> loaded = load_model(f.served());
  ASSERT_EQ(loaded->kind(), "calibrated");
  EXPECT_EQ(file_version(f.served()), r.version);
  const auto& published = dynamic_cast<const CalibratedModel&>(*loaded);
  EXPECT_EQ(published.emulator().state().x_train.rows(), 28);
  EXPECT_TRUE((published.problem().data().mu.array() == f.data.mu.array()).all());
  EXPECT_EQ(published.record().seed, f.sampler.seed);
  EXPECT_EQ(published.record().data_source, "measured.csv");
  // The independent path: the published emulator calibrated directly with the fixture's own data,
  // default priors and sampler.
  auto emulator = std::make_shared<const GaussianProcess>(published.emulator());
  EnsembleOptions sampler = f.sampler;
  sampler.max_steps = kDefaultCalibrationMaxSteps;
  const CalibrationResult direct = calibrate(CalibrationProblem(emulator, f.data, {"shear_factor"}, CalibrationPriors{}), sampler);
  ASSERT_EQ(published.record().posterior.size(), direct.summary.size());
  EXPECT_EQ(published.record().posterior[0].mean, direct.summary[0].mean);
  EXPECT_EQ(published.record().posterior[0].sd, direct.summary[0].sd);
  EXPECT_NEAR(direct.summary[0].mean, 0.35, 3.0 * direct.summary[0].sd + 0.01);
}

// Chains that cannot meet the limits (the served calibration's 40 steps, not continued) leave no
// candidate: the round is kept aside with the sampler's reason, and the served file stays.
TEST(Learning, ARecalibrationWhoseChainsAreNotUsableIsKeptAsideWithItsReason) {
  const CalibratedLearnerFixture f(40);
  learn_init(f.dir, f.setup());
  const std::string before = file_version(f.served());
  LearnRunOptions o = f.run(law_evaluator());
  o.recalibration_max_steps = 0;
  ASSERT_EQ(learn_rounds(f.dir, o).rounds_finished, 1);
  const LearnRound r = read_learn_state(f.dir).rounds.at(0);
  EXPECT_EQ(r.step, LearnStep::done);
  EXPECT_FALSE(r.gate.publish);
  EXPECT_NE(r.gate.reason.find("the recalibration's chains are not usable: "), std::string::npos) << r.gate.reason;
  EXPECT_TRUE(r.candidate.empty());
  EXPECT_EQ(file_version(f.served()), before);
}

}  // namespace
}  // namespace mufric
