// train, upgrade, describe, law, dataset from-model (eval and predict: predict_commands.cpp).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/fast_evaluator_options.hpp"
#include "client/friction_client.hpp"
#include "campaign/campaign_summary.hpp"
#include "common/csv_table.hpp"
#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"
#include "surrogate/core/accuracy.hpp"
#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/laws/empirical_laws.hpp"
#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/models/model_file.hpp"
#include "surrogate/gp/stochastic_kriging.hpp"

namespace mufric::app {
namespace {

std::string theta_text(const Eigen::VectorXd& theta) {
  std::string text;
  for (Eigen::Index i = 0; i < theta.size(); ++i) {
    char part[32];
    std::snprintf(part, sizeof part, "%s%.3g", i ? " " : "", std::exp(theta(i)));
    text += part;
  }
  return text;
}

void print_training_report(const GaussianProcess& gp, const GpTrainingReport& report) {
  const auto& s = gp.state();
  std::printf("restarts (hyper-parameters: signal variance, length scales..., noise variance)\n");
  for (size_t i = 0; i < report.starts.size(); ++i) {
    const auto& start = report.starts[i];
    std::printf("  start %zu%s  LML %14.6f  %4d evaluations (+%d on a subset)  %6.2f s  %s\n      from [%s]\n"
                "      to   [%s]\n",
                i, static_cast<int>(i) == report.best_start ? "*" : " ", start.log_marginal_likelihood,
                start.evaluations, start.subset_evaluations, start.seconds, start.outcome.c_str(),
                theta_text(start.initial_log).c_str(),
                theta_text(start.final_log).c_str());
  }
  std::printf("best: start %d, %s %.6f\n", report.best_start,
              s.mean_estimated ? "log restricted likelihood (REML, the mean estimated)" : "log marginal likelihood",
              s.summary.log_marginal_likelihood);
  std::printf("hyper-parameters:\n  signal variance %.6g (normalised mu units)\n", s.hyper.signal_variance);
  for (size_t j = 0; j < s.inputs.size(); ++j) {
    const auto& input = s.inputs[j];
    const double l = s.hyper.length_scales(static_cast<Eigen::Index>(j));
    const QuantityKind kind = input.kind();
    const double physical = l * (input.hi - input.lo);
    const double human = kind == QuantityKind::temperature ? physical : si_to_human(physical, kind);
    std::printf("  length scale %-18s %.6g box widths = %.4g %s\n", input.name.c_str(), l, human,
                std::string(kind == QuantityKind::temperature ? "K" : human_unit(kind)).c_str());
  }
  if (s.hyper.noise_term) {
    std::printf("  learned noise variance %.6g (normalised; std %.4g in mu)\n", s.hyper.noise_variance,
                s.y_scale * std::sqrt(s.hyper.noise_variance));
  }
  if (s.known_noise.size() != 0) {
    std::printf("  known per-sample noise on the diagonal: mean variance %.6g, max %.6g (normalised)\n",
                s.known_noise.mean(), s.known_noise.maxCoeff());
  }
  if (s.micro_std_error > 0) {
    std::printf("  micro-model scatter (RMS standard error of the samples' mu) %.4g = %.2f %% of mean mu: part of the "
                "served interval\n", s.micro_std_error, 100.0 * s.micro_std_error / std::max(std::abs(s.y_mean), 1e-300));
  }
  std::printf("interval: %s\n", gp_interval_meaning(gp.interval_meaning()).c_str());
  if (s.jitter > 0) std::printf("  jitter %.3g\n", s.jitter);
  const auto& t = s.summary;
  std::printf("cross-validation %s\n", leave_one_out_text(t, s.known_noise.size() != 0).c_str());
  for (const auto& w : report.warnings) std::printf("warning: %s\n", w.c_str());
}

// --extrapolation and --mu-range of train and upgrade: what the model file declares.
struct BoxOptions {
  std::string extrapolation;
  std::vector<double> mu_range;
};

void add_box_options(CLI::App* cmd, BoxOptions& o) {
  cmd->add_option("--extrapolation", o.extrapolation,
                  "The model's policy outside its training box: clamp (default: the model at the nearest point\n"
                  "of the box, flagged EXTRAPOLATED), raw (the model itself) or refuse (OUT_OF_BOX, no answer)")
      ->check(CLI::IsMember({"raw", "clamp", "refuse"}));
  cmd->add_option("--mu-range", o.mu_range, "Physical range of mu: answers and intervals are clipped to it (default 0 1)")
      ->expected(2);
}

// Training data must lie inside the μ range the model will declare: a row outside it (μ = 5 in a
// file of friction coefficients) is a mistake, and a range that excludes the data pins every
// answer to its edge (issue 30). Refused before the fit, naming the file and row.
void check_mu_within_range(const TrainingSet& data, const BoxOptions& o, const std::string& path) {
  const double lo = o.mu_range.empty() ? FrictionModel::kDefaultMuMin : o.mu_range[0];
  const double hi = o.mu_range.empty() ? FrictionModel::kDefaultMuMax : o.mu_range[1];
  for (Eigen::Index i = 0; i < data.mu.size(); ++i) {
    if (data.mu(i) < lo || data.mu(i) > hi) {
      char what[256];
      std::snprintf(what, sizeof what, "%s: converged sample %lld, column mu: %g is outside the "
                                       "model's mu range [%g, %g]%s",
                    path.c_str(), static_cast<long long>(i + 1), data.mu(i), lo, hi,
                    o.mu_range.empty() ? " (--mu-range LO HI declares another)" : " given by --mu-range");
      throw Error(what);
    }
  }
}

void apply_box_options(FrictionModel& model, const BoxOptions& o) {
  if (!o.extrapolation.empty()) model.set_default_extrapolation(extrapolation_from_string(o.extrapolation));
  if (!o.mu_range.empty()) model.set_mu_range(o.mu_range[0], o.mu_range[1]);
}

void add_train(CLI::App& app) {
  struct Options {
    std::string data, out;
    GpTrainingOptions gp;
    bool no_noise = false;
    bool no_stochastic_kriging = false;
    FastOptions fast;
    BoxOptions box;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("train", "Fit a Gaussian-process surrogate (RBF-ARD kernel) to a dataset");
  cmd->add_option("--data", o->data, "Dataset: mufric HDF5 file, or CSV with header like contact_pressure[MPa],...,mu")
      ->required();
  cmd->add_option("--out", o->out, "Model file to write (HDF5)")->required();
  cmd->add_option("--restarts", o->gp.restarts, "Optimiser starts after the first (log-uniform in the bounds)")
      ->capture_default_str()->check(CLI::Range(0, 1000));
  cmd->add_option("--seed", o->gp.seed, "Seed of the restart points")->capture_default_str();
  cmd->add_option("--threads", o->gp.threads, "Starts run in parallel on this many threads (0: the cores this process may use, at most OMP_NUM_THREADS)")
      ->capture_default_str();
  cmd->add_option("--max-evaluations", o->gp.max_evaluations, "LML evaluations per start")->capture_default_str();
  cmd->add_option("--subset", o->gp.subset_size,
                  "Each start first climbs the LML of a random subset of this many points, then all data "
                  "(0: off; used when the data have more than twice as many points)")
      ->capture_default_str()->check(CLI::Range(0, 1000000));
  cmd->add_flag("--no-noise", o->no_noise, "No white-noise term (interpolate exactly)");
  cmd->add_flag("--sample-noise", o->gp.sample_noise,
                "Put each sample's own variance (/samples/mu_std squared) on the covariance diagonal beside the\n"
                "learned noise. For samples whose errors are independent; a micro-model plan's samples share\n"
                "their tool draws, so their errors are correlated and this is off by default");
  cmd->add_flag("--no-stochastic-kriging", o->no_stochastic_kriging,
                "For a dataset of independent draws (dataset plan's default): train as for common draws instead\n"
                "(one GP, the samples' RMS standard error added to the interval), e.g. to compare the two");
  add_fast_evaluator_options(cmd, o->fast);
  add_box_options(cmd, o->box);
  cmd->footer("A dataset of independent draws (each sample its own tool and chip surfaces, per-draw mu recorded)\n"
              "is trained by stochastic kriging: first the patch scatter, a GP of the log per-draw variance of mu,\n"
              "then the mean, each sample's smoothed variance of its mean on the diagonal; the served interval is\n"
              "that of mu averaged over all draws and shrinks as the campaign grows, and the patch scatter is\n"
              "served on its own (patch_std). Other data: one GP, as before.\n"
              "Prints every start, the chosen hyper-parameters, the log marginal likelihood and a leave-one-out\n"
              "cross-validated error. Bounds: signal variance 1e-3..1e5, length scales 1e-2..1e3 box widths,\n"
              "noise variance 1e-6..1e-1 (outputs normalised to zero mean and unit variance).\n"
              "Then builds the certified fast evaluator (a grid of mu and log std with a measured error bound;\n"
              "`mufric describe` shows it): requests whose tolerances its bound meets get it inside the box.");
  cmd->callback([o] {
    o->gp.noise_term = !o->no_noise;
    const Dataset dataset = read_dataset_isolated(o->data);
    TrainingSet data = training_set(dataset, o->data);
    data.description = campaign_summary(dataset);
    std::printf("training data: %s (%lld converged of %s, %s)\n", o->data.c_str(), static_cast<long long>(data.x.rows()),
                count_of(dataset.size(), "sample", "samples").c_str(),
                count_of(static_cast<long long>(data.inputs.size()), "input", "inputs").c_str());
    if (data.outside_model > 0) {
      std::printf("left out: %lld samples outside the model (molten chip; `mufric dataset status` lists them)\n",
                  data.outside_model);
    }
    if (!dataset.note.empty()) std::printf("note: %s\n", dataset.note.c_str());
    if (!o->box.mu_range.empty() && !(o->box.mu_range[0] < o->box.mu_range[1])) {
      throw Error("--mu-range: the lower end must lie below the upper end");
    }
    check_mu_within_range(data, o->box, o->data);
    GpTrainingReport report;
    o->gp.progress = [](const std::string& line) {
      std::printf("  fit: %s\n", line.c_str());
      std::fflush(stdout);
    };
    const bool kriging = suits_stochastic_kriging(data) && !o->no_stochastic_kriging;
    if (kriging && o->gp.sample_noise) {
      throw Error("--sample-noise: a dataset of independent draws is trained by stochastic kriging, which puts each "
                  "sample's smoothed variance on the diagonal; give --no-stochastic-kriging to use the raw ones");
    }
    std::optional<GaussianProcess> trained;
    if (kriging) {
      StochasticKrigingReport sk;
      std::printf("stochastic kriging: %s of independent draws; first the patch scatter (a GP of the log per-draw "
                  "variance of mu), then the mean\n", count_of(data.x.rows(), "sample", "samples").c_str());
      std::fflush(stdout);
      trained.emplace(train_stochastic_kriging(data, o->gp, &sk));
      report = sk.mean;
      if (sk.homoscedastic) {
        std::printf("one draw per sample (%lld draws): no patch scatter to learn; the learned noise is the per-draw "
                    "variance, left out of the served interval (the mean's)\n", sk.draws);
      } else {
        std::printf("patch scatter: %lld samples, %lld draws; per-draw std of mu at the training points, median %.4g "
                    "(%.1f %% of mean mu); a sample's mean's smoothed standard error, median %.4g\n",
                    sk.scatter_samples, sk.draws, sk.median_patch_std,
                    100.0 * sk.median_patch_std / std::max(std::abs(data.mu.mean()), 1e-300), sk.median_sample_std_error);
        for (const auto& w : sk.scatter.warnings) std::printf("warning (patch scatter): %s\n", w.c_str());
      }
    } else {
      if (data.draws == DrawDesign::independent && !o->no_stochastic_kriging) {
        std::printf("note: the dataset's draws are independent but its samples carry no per-draw mu: one GP, as for "
                    "common draws\n");
      }
      trained.emplace(train_gaussian_process(data, o->gp, &report));
    }
    GaussianProcess& gp = *trained;
    print_training_report(gp, report);
    apply_box_options(gp, o->box);  // before the grid: it tabulates μ as served (clipped to the range)
    attach_fast_evaluator(gp, o->fast);
    save_model(o->out, gp);
    const FastEvaluator* fast = gp.fast_evaluator();
    std::printf("wrote %s (gp, %lld training points) in %.2f s; %s\n", o->out.c_str(),
                static_cast<long long>(data.x.rows()), report.seconds,
                fast == nullptr ? "no fast evaluator: the exact GP answers every request (see above why)"
                : fast->meets(o->fast.build.mu_tolerance, o->fast.build.std_relative_tolerance)
                    ? "its fast evaluator answers default requests"
                    : "its fast evaluator stopped short of the tolerances: the exact GP answers requests that ask more");
  });
}

void add_describe(CLI::App& app) {
  auto model_uri = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("describe", "Inputs, units, training box and accuracy figures of a model");
  cmd->add_option("model", *model_uri, "Model file or file:// URI, a shipped model's name (dry_default), or a served model: grpc://host:port/model")->required();
  cmd->callback([model_uri] {
    auto print_inputs = [](const InputSpace& inputs) {
      for (const auto& input : inputs) {
        std::printf("  %-18s [%s, %s]  stored in %s\n", input.name.c_str(), format_human(input.lo, input.kind()).c_str(),
                    format_human(input.hi, input.kind()).c_str(), input.unit.c_str());
      }
    };
    if (model_uri->rfind("grpc://", 0) == 0 || model_uri->rfind("grpcs://", 0) == 0) {
      const client::ModelInfo info = client::connect(*model_uri)->describe();
      std::printf("%s: model %s, version %s, kind %s\ninputs (training box):\n", model_uri->c_str(), info.name.c_str(),
                  info.version.c_str(), info.kind.c_str());
      print_inputs(info.inputs);
      std::printf("%s\n", info.summary.c_str());
      return;
    }
    const auto model = load_model_isolated(model_path_from_uri(*model_uri));
    std::printf("%s: kind %s\ninputs (training box):\n", model_uri->c_str(), std::string(model->kind()).c_str());
    print_inputs(model->inputs());
    if (const std::string why = servable_inputs_violation(input_names(model->inputs())); !why.empty()) {
      std::printf("not served: %s\n", why.c_str());
    }
    std::printf("outside the box: %s (a request may choose raw, clamp or refuse); mu kept in [%g, %g]\n",
                std::string(to_string(model->default_extrapolation())).c_str(), model->mu_min(), model->mu_max());
    std::printf("%s\n", model->summary().c_str());
  });
}

void add_law(CLI::App& app) {
  auto* law = app.add_subcommand("law", "Write an empirical friction law as a model file");
  law->require_subcommand(1);
  struct Options {
    std::string out, csv;
    double mu = 0.3;
    int table = 4;
  };
  auto o = std::make_shared<Options>();
  auto* coulomb = law->add_subcommand("coulomb", "Constant friction coefficient");
  coulomb->add_option("--mu", o->mu, "The coefficient")->required()->check(FiniteRange(0.0, 10.0));
  coulomb->add_option("--out", o->out, "Model file to write")->required();
  coulomb->callback([o] {
    save_model(o->out, CoulombLaw(o->mu));
    std::printf("wrote %s (coulomb, mu = %g)\n", o->out.c_str(), o->mu);
  });
  auto* seward = law->add_subcommand("seward", "Seed 001 (Seward et al. 2022) MLR law mu(p, v, fibre angle)");
  seward->add_option("--table", o->table, "2: apparent COF (Table 2), 4: adhesive COF (Table 4)")
      ->capture_default_str()->check(CLI::IsMember({2, 4}));
  seward->add_option("--out", o->out, "Model file to write")->required();
  seward->callback([o] {
    const MlrLaw law_model = o->table == 2 ? MlrLaw::seed001_table2() : MlrLaw::seed001_table4();
    save_model(o->out, law_model);
    std::printf("%s\nwrote %s\n", law_model.summary().c_str(), o->out.c_str());
  });
  auto* fit = law->add_subcommand("fit", "Least-squares MLR law per fibre angle from measurements");
  fit->add_option("--csv", o->csv, "CSV: fibre_angle[deg],contact_pressure[MPa],sliding_velocity[m/min],mu")
      ->required();
  fit->add_option("--out", o->out, "Model file to write")->required();
  fit->callback([o] {
    MlrFitReport report;
    const MlrLaw law_model = fit_mlr_law(o->csv, &report);
    std::printf("%s\n", law_model.summary().c_str());
    for (const auto& a : report.angles) {
      std::printf("  fibre angle %7.2f deg: %lld samples, R^2 = %.4f\n", a.fibre_angle_deg, a.samples, a.r_squared);
    }
    save_model(o->out, law_model);
    std::printf("wrote %s\n", o->out.c_str());
  });
}

void add_dataset_from_model(CLI::App& app) {
  auto* dataset = app.add_subcommand("dataset", "Training databases (HDF5)");
  dataset->require_subcommand(1);
  struct Options {
    std::string model, out;
    SamplingOptions sampling;
  };
  auto o = std::make_shared<Options>();
  auto* from_model = dataset->add_subcommand(
      "from-model", "Sample a model (e.g. an empirical law) on a Latin hypercube of its box into a dataset file");
  from_model->add_option("--model", o->model, "Model file or file:// URI, or a shipped model's name (dry_default)")->required();
  from_model->add_option("--samples", o->sampling.samples, "Number of samples")->capture_default_str()
      ->check(CLI::Range(1, 10000000));
  from_model->add_option("--seed", o->sampling.seed, "Random seed")->capture_default_str();
  from_model->add_option("--noise", o->sampling.noise_std, "Std of additive Gaussian noise on mu")
      ->capture_default_str()->check(FiniteRange(0.0, 1.0));
  from_model->add_option("--out", o->out, "Dataset file to write (HDF5)")->required();
  from_model->callback([o] {
    const auto model = load_model_isolated(model_path_from_uri(o->model));
    const Dataset data = sample_model(*model, o->sampling, "model:" + o->model);
    write_dataset(o->out, data);
    std::printf("wrote %s: %lld samples of %s (seed %llu, noise std %g)\n", o->out.c_str(),
                static_cast<long long>(data.size()), o->model.c_str(),
                static_cast<unsigned long long>(o->sampling.seed), o->sampling.noise_std);
  });
}

}  // namespace

void add_upgrade(CLI::App& app) {
  struct Options {
    std::string model, out;
    bool rebuild = false;
    FastOptions fast;
    BoxOptions box;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("upgrade", "Rewrite a model file in the current schema, adding a GP's or a calibrated model's fast evaluator");
  cmd->add_option("model", o->model, "Model file (any readable schema version)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out, "Where to write (default: replace the file, atomically)");
  cmd->add_flag("--rebuild", o->rebuild, "Rebuild the fast evaluator even if the file has one");
  add_fast_evaluator_options(cmd, o->fast);
  add_box_options(cmd, o->box);
  cmd->callback([o] {
    auto model = load_model_isolated(o->model);
    const bool range_changed = !o->box.mu_range.empty();
    apply_box_options(*model, o->box);
    const bool build = o->fast.skip || o->rebuild || range_changed;
    // A GP's grids and a calibrated model's alike: built when missing or asked, else kept.
    const auto grid = [&](auto& gridded) {
      if (gridded.fast_evaluator() == nullptr || build) {
        attach_fast_evaluator(gridded, o->fast);
      } else {
        std::printf("keeps its fast evaluator (--rebuild to build it again)\n");
      }
    };
    if (auto* gp = dynamic_cast<GaussianProcess*>(model.get())) {
      grid(*gp);
    } else if (auto* calibrated = dynamic_cast<CalibratedModel*>(model.get())) {
      grid(*calibrated);
    }
    const std::string out = o->out.empty() ? o->model : o->out;
    save_model(out, *model);
    std::printf("wrote %s (%s, schema version %lld)\n", out.c_str(), std::string(model->kind()).c_str(),
                kModelSchemaVersion);
  });
}

void add_surrogate_commands(CLI::App& app) {
  add_train(app);
  add_upgrade(app);
  add_predict_commands(app);
  add_describe(app);
  add_law(app);
  add_dataset_from_model(app);
}

}  // namespace mufric::app
