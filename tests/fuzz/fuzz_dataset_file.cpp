// Dataset-file reading from arbitrary bytes: read_dataset and the training set built from it either
// refuse with mufric::Error or give finite inputs and mu. Crashes inside libhdf5 are triaged by
// tests/fuzz/run_fuzzers.sh (see fuzz_model_file.cpp).
#include <cmath>
#include <cstdlib>

#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = mufric::fuzz::write_input(data, size, ".h5");
  try {
    const mufric::Dataset d = mufric::read_dataset(path);
    const mufric::TrainingSet t = mufric::training_set(d, path);
    if (!t.x.allFinite() || !t.mu.allFinite()) std::abort();
  } catch (const mufric::Error&) {
  }
  return 0;
}
