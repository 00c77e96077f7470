// `mufric eval` (a model against held-out samples) and `mufric predict` (μ and its interval at points
// given as flags or a CSV, optionally with gradients).
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/input_flags.hpp"
#include "client/friction_client.hpp"
#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"
#include "surrogate/core/accuracy.hpp"
#include "surrogate/models/model_file.hpp"


namespace mufric::app {
namespace {

void add_eval(CLI::App& app) {
  struct Options {
    std::string model, test;
    double level = 0.95;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("eval", "Held-out accuracy of a model on a test dataset");
  cmd->add_option("--model", o->model, "Model file or file:// URI, or a shipped model's name (dry_default)")->required();
  cmd->add_option("--test", o->test, "Test dataset (HDF5 or CSV), not used in training")->required();
  cmd->add_option("--level", o->level, "Confidence level of the interval whose coverage is reported")
      ->capture_default_str()->check(FiniteRange(0.5, 0.9999));
  cmd->callback([o] {
    const auto model = load_model_isolated(model_path_from_uri(o->model));
    const TrainingSet test = training_set(read_dataset_isolated(o->test), o->test);
    const AccuracyReport r = held_out_accuracy(*model, test, o->level);
    std::printf("model %s (%s) on %s: %s (%lld outside the training box)\n", o->model.c_str(),
                std::string(model->kind()).c_str(), o->test.c_str(), count_of(r.points, "point", "points").c_str(), r.extrapolated);
    std::printf("mean relative error %.4f %%\nmax relative error  %.4f %%\nRMSE                %.4g\n"
                "%.0f %% interval coverage %.1f %%\nevaluation          %.3g us per point (mean + interval)\n",
                100 * r.mean_relative_error, 100 * r.max_relative_error, r.rmse, 100 * o->level, 100 * r.coverage,
                1e6 * r.seconds_per_point);
    if (!model->has_uncertainty()) std::printf("note: a %s model has no uncertainty: its interval has zero width\n",
                                               std::string(model->kind()).c_str());
  });
}


// The points to ask: one from the flags, or every row of --csv (columns named like the model's
// inputs, with units).
struct PredictPoints {
  std::vector<std::vector<double>> columns;  // SI, per model input: what the block points into
  std::vector<int> lines;                    // CSV line of each point (empty for flags)
};

PredictPoints points_from_csv(const std::string& path, const InputSpace& inputs) {
  const CsvTable table = read_csv_table(path);
  for (const auto& c : table.columns) {
    const bool used = std::any_of(inputs.begin(), inputs.end(), [&](const InputSpec& s) { return s.name == c.name; });
    if (!used) throw Error(path + ": column '" + c.name + "' is not an input of the model");
  }
  PredictPoints p;
  for (const auto& input : inputs) {
    if (!table.has_column(input.name)) {
      throw Error(path + ": no column '" + input.name + "' (the model's input; e.g. " + input.name + "[" +
                  std::string(human_unit(input.kind())) + "])");
    }
    p.columns.push_back(table.si_column(input.name));
  }
  p.lines = table.line_of_row;
  if (p.lines.empty()) throw Error(path + ": a header and no rows: no point to predict");
  return p;
}

// What an EXTRAPOLATED answer is (docs/usage.md, "Outside the box"): under clamp, μ of the nearest
// point of the box with an interval widened by the distance; under raw, the model itself beyond its data.
std::string extrapolation_account(const InputSpace& inputs, const PredictPoints& points, Extrapolation policy) {
  if (policy != Extrapolation::clamp) {
    return "answered by the raw model beyond its data (policy raw): its interval says how little it knows there";
  }
  std::vector<double> first(inputs.size());
  for (size_t j = 0; j < inputs.size(); ++j) first[j] = points.columns[j][0];
  return "answered at " + clamped_face_text(inputs, first.data()) + " (policy clamp: mu of the nearest point of the box, its interval widened by the "
         "distance; --extrapolation raw or refuse to choose otherwise)";
}

// dμ/dx in per-human-unit (per MPa, per m/min, per °C), as the inputs are given.
double gradient_per_human_unit(double per_si, QuantityKind kind) {
  return per_si * unit_to_si(human_unit(kind)).scale;
}

void add_predict(CLI::App& app) {
  struct Options {
    std::string model, csv, out;
    std::map<std::string, std::string> values;  // flag → text
    double level = 0.95;
    bool gradient = false;
    std::string extrapolation;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("predict", "Friction coefficients with their confidence intervals, human units");
  cmd->add_option("--model", o->model, "Model: file:///path/model.h5 (or a path), a shipped model's name (dry_default), or grpc://host:port/model")->required();
  for (const KnownInput& input : known_inputs()) {  // --p, --v, --T, --angle: what a client carries
    if (!input.on_the_wire) continue;
    const std::string flag(flag_of(input.name));
    cmd->add_option(flag, o->values[flag],
                    "The " + std::string(input.name) + " with its unit, e.g. " + std::string(example_quantity(input.kind)));
  }
  cmd->add_option("--csv", o->csv,
                  "Many points: a CSV whose columns are the model's inputs with units, e.g.\n"
                  "contact_pressure[MPa],sliding_velocity[m/min],temperature[C]; writes a CSV of mu, std, lo, hi,\n"
                  "status and the reason of a point that is not OK")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out, "With --csv: write the answers here (default: standard output)");
  cmd->add_option("--level", o->level, "Confidence level of the interval")->capture_default_str()
      ->check(FiniteRange(0.5, 0.9999));
  cmd->add_flag("--gradient", o->gradient, "Also print dmu/dinput, per the input's human unit (per MPa, m/min, C)");
  cmd->add_option("--extrapolation", o->extrapolation,
                  "Outside the training box: raw, clamp or refuse (default: the model file's policy)")
      ->check(CLI::IsMember({"raw", "clamp", "refuse"}));
  cmd->footer("Exit status 2 when a point gets no answer (INVALID_INPUT: impossible values; OUT_OF_BOX: outside the\n"
              "box under --extrapolation refuse), with the reason; EXTRAPOLATED points are answered and say why.");
  cmd->callback([o] {
    client::Options options;
    options.isolate_file_parsing = true;  // a command-line tool: a corrupt file is an error, not a crash
    const auto client = client::connect(o->model, options);
    const client::ModelInfo info = client->describe();
    const InputSpace& inputs = info.inputs;
    const bool from_csv = !o->csv.empty();
    PredictPoints points;
    if (from_csv) {
      for (const KnownInput& input : known_inputs()) {
        const std::string flag(flag_of(input.name));
        if (input.on_the_wire && !o->values[flag].empty()) throw Error(flag + " and --csv exclude each other");
      }
      points = points_from_csv(o->csv, inputs);
    } else {
      if (!o->out.empty()) throw Error("--out goes with --csv");
      for (const auto& input : inputs) {
        const std::string flag(flag_of(input.name));
        if (flag.empty()) throw Error("model input '" + input.name + "' has no command-line flag (use --csv)");
        const std::string& text = o->values[flag];
        if (text.empty()) throw Error(flag + " is required: the model's input " + input.name + " (e.g. " + flag + " " +
                                      std::string(example_quantity(input.kind())) + ")");
        points.columns.push_back({parse_quantity(text, input.kind(), flag)});
      }
      for (const KnownInput& known : known_inputs()) {
        if (!known.on_the_wire) continue;
        const bool used = std::any_of(inputs.begin(), inputs.end(), [&](const InputSpec& s) { return s.name == known.name; });
        const std::string flag(flag_of(known.name));
        if (!used && !o->values[flag].empty()) {
          throw Error(flag + " was given but the model has no input " + std::string(known.name));
        }
      }
    }
    const size_t n = points.columns.empty() ? 0 : points.columns.front().size();
    client::Block block{.points = n};
    for (size_t j = 0; j < inputs.size(); ++j) {
      if (const auto field = client::Block::field_for(inputs[j].name)) block.*field = points.columns[j].data();
    }
    EvaluationRequest what{.std = true, .ci_level = o->level, .gradient = o->gradient, .patch_std = true};
    if (!o->extrapolation.empty()) what.extrapolation = extrapolation_from_string(o->extrapolation);
    const client::Answer a = client->evaluate(block, what);
    const bool patch = a.patch_std.size() == n && n > 0;  // the model has a patch scatter
    std::vector<double> x(inputs.size());
    auto reason_of = [&](size_t i) {
      for (size_t j = 0; j < inputs.size(); ++j) x[j] = points.columns[j][i];
      return point_reason(inputs, x.data());
    };
    long long unanswered = 0;
    std::string first_unanswered;
    for (size_t i = 0; i < n; ++i) {
      if (has_no_answer(a.status[i])) {
        if (unanswered++ == 0) {
          first_unanswered = (from_csv ? o->csv + ": line " + std::to_string(points.lines[i]) + ": " : std::string()) +
                             std::string(to_string(a.status[i])) + ": " + reason_of(i);
        }
      }
    }
    if (from_csv) {
      std::FILE* out = o->out.empty() ? stdout : std::fopen(o->out.c_str(), "w");
      if (out == nullptr) throw Error(o->out + ": cannot write");
      for (const auto& input : inputs) std::fprintf(out, "%s[%s],", input.name.c_str(), std::string(human_unit(input.kind())).c_str());
      std::fprintf(out, "mu,std,lo,hi,status,reason%s\n", patch ? ",patch_std" : "");
      for (size_t i = 0; i < n; ++i) {
        for (size_t j = 0; j < inputs.size(); ++j) std::fprintf(out, "%.10g,", si_to_human(points.columns[j][i], inputs[j].kind()));
        const std::string reason = a.status[i] == PointStatus::ok ? std::string() : reason_of(i);
        std::fprintf(out, "%.10g,%.6g,%.10g,%.10g,%s,\"%s\"", a.mu[i], a.std[i], a.lo[i], a.hi[i],
                     std::string(to_string(a.status[i])).c_str(), reason.c_str());
        if (patch) std::fprintf(out, ",%.6g", a.patch_std[i]);
        std::fprintf(out, "\n");
      }
      if (out != stdout && std::fclose(out) != 0) throw Error(o->out + ": write failed");
      std::fprintf(stderr, "%s (%lld answered by the fast evaluator)\n", count_of(static_cast<long long>(n), "point", "points").c_str(),
                   a.fast_points);
    } else if (!has_no_answer(a.status[0])) {  // a point without an answer gets its error line alone
      for (size_t j = 0; j < inputs.size(); ++j) {
        std::printf("%s%s = %s", j ? ", " : "", inputs[j].name.c_str(), format_human(points.columns[j][0], inputs[j].kind()).c_str());
      }
      std::printf("\nmu = %.6g  std %.3g  %.0f %% interval [%.6g, %.6g]  status %s  (%s)\n", a.mu[0], a.std[0],
                  100 * o->level, a.lo[0], a.hi[0], std::string(to_string(a.status[0])).c_str(),
                  a.fast_points > 0 ? "fast evaluator" : "exact model");
      if (a.status[0] == PointStatus::extrapolated) {
        std::printf("  outside the training box: %s\n", reason_of(0).c_str());
        std::printf("  %s\n", extrapolation_account(inputs, points, effective_extrapolation(what.extrapolation, info.extrapolation)).c_str());
      }
      if (patch) {
        std::printf("  patch scatter %.3g: one contact patch's mu scatters about this mean with this standard deviation "
                    "(the micro-model's per-draw spread; not part of the interval)\n", a.patch_std[0]);
      }
      if (o->gradient && !has_no_answer(a.status[0])) {
        for (size_t j = 0; j < inputs.size(); ++j) {
          std::printf("  dmu/d%s = %.6g per %s\n", inputs[j].name.c_str(),
                      gradient_per_human_unit(a.gradient[j], inputs[j].kind()), std::string(human_unit(inputs[j].kind())).c_str());
        }
      }
    }
    if (unanswered > 0) {
      throw Error(first_unanswered + more_points_tail(unanswered - 1, false));
    }
  });
}

}  // namespace

void add_predict_commands(CLI::App& app) {
  add_eval(app);
  add_predict(app);
}

}  // namespace mufric::app
