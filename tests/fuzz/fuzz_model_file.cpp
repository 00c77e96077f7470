// Model-file loading from arbitrary bytes: load_model must refuse with mufric::Error or accept a
// model whose every prediction is finite. A crash inside libhdf5 itself is the HDF5 library's (the
// CLI and the server parse untrusted files in a child process for that reason, common/isolation.hpp);
// tests/fuzz/run_fuzzers.sh tells those apart from crashes in mufric's own code.
#include <cmath>
#include <cstdlib>

#include "common/error.hpp"
#include "fuzz_support.hpp"
#include "surrogate/models/model_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = mufric::fuzz::write_input(data, size, ".h5");
  try {
    const auto model = mufric::load_model(path);
    mufric::QueryBatch x(4, static_cast<Eigen::Index>(model->inputs().size()));
    for (Eigen::Index j = 0; j < x.cols(); ++j) {
      const auto& input = model->inputs()[static_cast<size_t>(j)];
      x.col(j) << input.lo, input.hi, 0.5 * (input.lo + input.hi), input.hi + (input.hi - input.lo);
    }
    const mufric::Evaluation e = model->evaluate(x, {.std = true, .ci_level = 0.95, .gradient = true});
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      // An accepted model answers every valid point with a finite mu: a loaded file that predicts
      // inf or NaN inside its own box is exactly what validation exists to refuse.
      if (e.status[static_cast<size_t>(i)] != mufric::PointStatus::invalid_input && !std::isfinite(e.mu(i))) std::abort();
    }
  } catch (const mufric::Error&) {
  }
  return 0;
}
