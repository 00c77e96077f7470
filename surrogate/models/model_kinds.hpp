#pragma once
// The model kinds a model file can hold, each registered by its name with its reader, as the
// interface laws are (micro/contact/interface_laws.hpp): a kind's writing is its FrictionModel::write,
// its reading and checks are its own (gaussian_process_file.cpp, empirical_laws.cpp,
// calibrated_model.cpp), and model_file.cpp keeps only the file's frame and this lookup. A new kind
// is one class and one line in model_kinds.cpp (docs/design.md, "How a module takes its options").
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/h5_file.hpp"
#include "common/input_space.hpp"
#include "surrogate/core/friction_model.hpp"

namespace mufric {

struct ModelKindEntry {
  std::string_view name;     // the file's "kind" attribute, FrictionModel::kind()
  std::string_view summary;  // a line for messages and docs
  // Reads the kind's own groups of an open file whose frame (format, version, inputs) is checked;
  // throws Error (or lets h5::Reader::fail name the field) for a group it refuses.
  std::function<std::unique_ptr<FrictionModel>(const h5::Reader& in, InputSpace inputs)> read;
};
const std::vector<ModelKindEntry>& model_kinds();
// The entry of `name`; none when no kind has it.
const ModelKindEntry* find_model_kind(std::string_view name);
// The registered names, comma-separated, for messages.
std::string model_kind_names();

}  // namespace mufric
