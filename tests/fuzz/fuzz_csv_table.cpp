// CSV tables with units ("contact_pressure[MPa],...,mu"): read as a table, as a training dataset and
// as an MLR law fit. Arbitrary bytes end in mufric::Error or in finite SI values.
#include <cmath>
#include <cstdlib>

#include "common/csv_table.hpp"
#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "fuzz_support.hpp"
#include "surrogate/laws/empirical_laws.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = mufric::fuzz::write_input(data, size, ".csv");
  try {
    const mufric::CsvTable table = mufric::read_csv_table(path);
    for (const auto& column : table.columns) {
      try {
        for (const double v : table.si_column(column.name)) {
          if (!std::isfinite(v)) std::abort();
        }
      } catch (const mufric::Error&) {
      }
    }
  } catch (const mufric::Error&) {
  }
  try {
    const mufric::TrainingSet t = mufric::training_set(mufric::read_dataset(path), path);
    if (!t.x.allFinite() || !t.mu.allFinite()) std::abort();
  } catch (const mufric::Error&) {
  }
  try {
    mufric::fit_mlr_law(path);
  } catch (const mufric::Error&) {
  }
  return 0;
}
