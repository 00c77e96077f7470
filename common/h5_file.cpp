#include "common/h5_file.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>

#include "common/error.hpp"

namespace mufric::h5 {
namespace {

H5::StrType variable_string_type() { return H5::StrType(H5::PredType::C_S1, H5T_VARIABLE); }

// H5Lexists on every component, because it fails (rather than answering false) for a missing parent.
bool link_exists(hid_t file, const std::string& path) {
  std::string partial;
  std::stringstream parts(path);
  std::string part;
  while (std::getline(parts, part, '/')) {
    if (part.empty()) continue;
    partial += "/" + part;
    if (H5Lexists(file, partial.c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return true;
}

std::vector<hsize_t> dims_of(const H5::DataSet& ds) {
  H5::DataSpace space = ds.getSpace();
  const int rank = space.getSimpleExtentNdims();
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  if (rank > 0) space.getSimpleExtentDims(dims.data());
  return dims;
}

// The product of `dims`, or nothing when it overflows.
std::optional<hsize_t> count_of(const std::vector<hsize_t>& dims) {
  hsize_t n = 1;
  for (hsize_t d : dims) {
    if (d != 0 && n > std::numeric_limits<hsize_t>::max() / d) return std::nullopt;
    n *= d;
  }
  return n;
}

// Every value mufric stores takes at least this many bytes in the file: 8 for a double or an
// integer, 16 for a variable-length string's global-heap reference.
constexpr size_t kBytesPerNumber = 8;
constexpr size_t kBytesPerString = 16;

}  // namespace

void quiet_hdf5_errors() { H5::Exception::dontPrint(); }

Reader::Reader(const std::string& path, const std::string& what) : path_(path), what_(what) {
  quiet_hdf5_errors();
  if (!std::filesystem::exists(path)) throw Error(what + " '" + path + "': no such file");
  if (std::filesystem::is_directory(path)) throw Error(what + " '" + path + "': a directory, not a file");
  std::error_code size_error;
  file_bytes_ = std::filesystem::file_size(path, size_error);
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    throw Error(what + " '" + path + "': not an HDF5 file (corrupt, truncated or another format)");
  }
  try {
    file_ = H5::H5File(path, H5F_ACC_RDONLY);
  } catch (const H5::Exception& e) {
    throw Error(what + " '" + path + "': cannot be opened as HDF5 (" + e.getDetailMsg() + ")");
  }
}

void Reader::fail(const std::string& object, const std::string& problem) const {
  throw Error(what_ + " '" + path_ + "': " + object + ": " + problem);
}

bool Reader::has(const std::string& object) const {
  return object == "/" || link_exists(file_.getId(), object);
}

H5::DataSet Reader::open_dataset(const std::string& dataset) const {
  if (!has(dataset)) fail(dataset, "missing");
  try {
    return file_.openDataSet(dataset);
  } catch (const H5::Exception& e) {
    fail(dataset, "unreadable (" + e.getDetailMsg() + ")");
  }
}

size_t Reader::value_count(const std::string& dataset, const H5::DataSet& ds, size_t min_bytes_per_value) const {
  std::vector<hsize_t> dims;
  try {
    dims = dims_of(ds);
  } catch (const H5::Exception& e) {
    fail(dataset, "unreadable shape (" + e.getDetailMsg() + ")");
  }
  const auto count = count_of(dims);
  if (!count || *count > file_bytes_ / min_bytes_per_value) {
    fail(dataset, "declares more values than the file (" + std::to_string(file_bytes_) + " bytes) can hold: corrupt");
  }
  return static_cast<size_t>(*count);
}

H5::H5Object& Reader::object_for_attribute(const std::string& object, H5::Group& group_storage) const {
  if (object == "/") return file_;
  if (!has(object)) fail(object, "missing");
  try {
    group_storage = file_.openGroup(object);
  } catch (const H5::Exception&) {
    fail(object, "is not a group");
  }
  return group_storage;
}

bool Reader::has_attribute(const std::string& object, const std::string& name) const {
  if (object != "/" && !has(object)) return false;
  H5::Group storage;
  return object_for_attribute(object, storage).attrExists(name);
}

H5::Attribute Reader::open_attribute(const std::string& object, const std::string& name,
                                     std::initializer_list<H5T_class_t> classes, const std::string& expected) const {
  H5::Group storage;
  H5::H5Object& owner = object_for_attribute(object, storage);
  if (!owner.attrExists(name)) fail(object, "missing attribute '" + name + "'");
  try {
    H5::Attribute attribute = owner.openAttribute(name);
    const H5T_class_t found = attribute.getTypeClass();
    if (std::find(classes.begin(), classes.end(), found) == classes.end()) {
      fail(object, "attribute '" + name + "' is not " + expected);
    }
    return attribute;
  } catch (const H5::Exception& e) {
    fail(object, "attribute '" + name + "' unreadable (" + e.getDetailMsg() + ")");
  }
}

void Reader::read_attribute(const std::string& object, const std::string& name, const std::function<void()>& read) const {
  try {
    read();
  } catch (const H5::Exception& e) {
    fail(object, "attribute '" + name + "' unreadable (" + e.getDetailMsg() + ")");
  }
}

std::string Reader::string_attribute(const std::string& object, const std::string& name) const {
  H5::Attribute attribute = open_attribute(object, name, {H5T_STRING}, "a string");
  std::string value;
  read_attribute(object, name, [&] { attribute.read(attribute.getStrType(), value); });
  return value;
}

double Reader::double_attribute(const std::string& object, const std::string& name) const {
  double value = 0.0;
  H5::Attribute attribute = open_attribute(object, name, {H5T_FLOAT, H5T_INTEGER}, "a number");
  read_attribute(object, name, [&] { attribute.read(H5::PredType::NATIVE_DOUBLE, &value); });
  return value;
}

long long Reader::int_attribute(const std::string& object, const std::string& name) const {
  long long value = 0;
  H5::Attribute attribute = open_attribute(object, name, {H5T_INTEGER}, "an integer");
  read_attribute(object, name, [&] { attribute.read(H5::PredType::NATIVE_LLONG, &value); });
  return value;
}

void Reader::require_format(const std::string& format, long long version, const std::string& kind_of_file) const {
  require_format(format, version, version, kind_of_file);
}

long long Reader::require_format(const std::string& format, long long oldest, long long newest,
                                 const std::string& kind_of_file) const {
  if (!has_attribute("/", "format") || string_attribute("/", "format") != format) {
    fail("/", "not a " + kind_of_file + " (attribute 'format' is not '" + format + "')");
  }
  const long long found = int_attribute("/", "schema_version");
  if (found < oldest || found > newest) {
    fail("/", "schema_version " + std::to_string(found) + " is not supported (this build reads " +
                  (oldest == newest ? std::to_string(newest) : std::to_string(oldest) + " to " + std::to_string(newest)) + ")");
  }
  return found;
}

std::vector<double> Reader::doubles(const std::string& dataset) const {
  H5::DataSet ds = open_dataset(dataset);
  if (ds.getTypeClass() != H5T_FLOAT) fail(dataset, "is not floating point");
  std::vector<double> values(value_count(dataset, ds, kBytesPerNumber));
  try {
    if (!values.empty()) ds.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  } catch (const H5::Exception& e) {
    fail(dataset, "unreadable (" + e.getDetailMsg() + ")");
  }
  return values;
}

std::vector<long long> Reader::ints(const std::string& dataset) const {
  H5::DataSet ds = open_dataset(dataset);
  if (ds.getTypeClass() != H5T_INTEGER) fail(dataset, "is not integer");
  std::vector<long long> values(value_count(dataset, ds, kBytesPerNumber));
  try {
    if (!values.empty()) ds.read(values.data(), H5::PredType::NATIVE_LLONG);
  } catch (const H5::Exception& e) {
    fail(dataset, "unreadable (" + e.getDetailMsg() + ")");
  }
  return values;
}

std::vector<std::string> Reader::strings(const std::string& dataset) const {
  H5::DataSet ds = open_dataset(dataset);
  if (ds.getTypeClass() != H5T_STRING) fail(dataset, "is not a string array");
  const size_t n = value_count(dataset, ds, kBytesPerString);
  std::vector<char*> raw(n, nullptr);
  H5::StrType type = variable_string_type();
  try {
    if (n > 0) ds.read(raw.data(), type);
  } catch (const H5::Exception& e) {
    fail(dataset, "unreadable (" + e.getDetailMsg() + ")");
  }
  std::vector<std::string> values;
  values.reserve(n);
  for (char* s : raw) values.emplace_back(s ? s : "");
  if (n > 0) {
    H5::DataSpace space = ds.getSpace();
    H5Dvlen_reclaim(type.getId(), space.getId(), H5P_DEFAULT, raw.data());
  }
  return values;
}

RowMatrix Reader::matrix(const std::string& dataset) const {
  H5::DataSet ds = open_dataset(dataset);
  const auto dims = dims_of(ds);
  if (dims.size() != 2) fail(dataset, "expected a 2-D array, found rank " + std::to_string(dims.size()));
  if (ds.getTypeClass() != H5T_FLOAT) fail(dataset, "is not floating point");
  value_count(dataset, ds, kBytesPerNumber);
  RowMatrix values(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1]));
  try {
    if (values.size() > 0) ds.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  } catch (const H5::Exception& e) {
    fail(dataset, "unreadable (" + e.getDetailMsg() + ")");
  }
  return values;
}

Eigen::VectorXd Reader::vector(const std::string& dataset, Eigen::Index expected) const {
  const std::vector<double> values = doubles(dataset);
  if (static_cast<Eigen::Index>(values.size()) != expected) {
    fail(dataset, "has " + std::to_string(values.size()) + " values, expected " + std::to_string(expected));
  }
  return Eigen::Map<const Eigen::VectorXd>(values.data(), expected);
}

Writer::Writer(const std::string& path) : path_(path), temp_path_(path + ".tmp") {
  quiet_hdf5_errors();
  try {
    file_ = H5::H5File(temp_path_, H5F_ACC_TRUNC);
  } catch (const H5::Exception& e) {
    throw Error("cannot create '" + temp_path_ + "' (" + e.getDetailMsg() + ")");
  }
}

Writer::~Writer() {
  if (!committed_) {
    try {
      file_.close();
    } catch (...) {
    }
    std::remove(temp_path_.c_str());
  }
}

H5::H5Object& Writer::object(const std::string& name, H5::Group& storage) {
  if (name == "/") return file_;
  storage = file_.openGroup(name);
  return storage;
}

void Writer::group(const std::string& name) {
  if (!link_exists(file_.getId(), name)) file_.createGroup(name);
}

void Writer::string_attribute(const std::string& object_name, const std::string& name, const std::string& value) {
  H5::Group storage;
  H5::StrType type = variable_string_type();
  object(object_name, storage).createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, value);
}

void Writer::double_attribute(const std::string& object_name, const std::string& name, double value) {
  H5::Group storage;
  object(object_name, storage)
      .createAttribute(name, H5::PredType::IEEE_F64LE, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_DOUBLE, &value);
}

void Writer::int_attribute(const std::string& object_name, const std::string& name, long long value) {
  H5::Group storage;
  object(object_name, storage)
      .createAttribute(name, H5::PredType::STD_I64LE, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_LLONG, &value);
}

void Writer::doubles(const std::string& dataset, const std::vector<double>& values) {
  const hsize_t dims[1] = {values.size()};
  H5::DataSet ds = file_.createDataSet(dataset, H5::PredType::IEEE_F64LE, H5::DataSpace(1, dims));
  if (!values.empty()) ds.write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

void Writer::doubles(const std::string& dataset, const Eigen::VectorXd& values) {
  doubles(dataset, std::vector<double>(values.data(), values.data() + values.size()));
}

void Writer::ints(const std::string& dataset, const std::vector<long long>& values) {
  const hsize_t dims[1] = {values.size()};
  H5::DataSet ds = file_.createDataSet(dataset, H5::PredType::STD_I64LE, H5::DataSpace(1, dims));
  if (!values.empty()) ds.write(values.data(), H5::PredType::NATIVE_LLONG);
}

void Writer::strings(const std::string& dataset, const std::vector<std::string>& values) {
  const hsize_t dims[1] = {values.size()};
  H5::StrType type = variable_string_type();
  H5::DataSet ds = file_.createDataSet(dataset, type, H5::DataSpace(1, dims));
  std::vector<const char*> raw;
  raw.reserve(values.size());
  for (const auto& s : values) raw.push_back(s.c_str());
  if (!raw.empty()) ds.write(raw.data(), type);
}

void Writer::matrix(const std::string& dataset, const RowMatrix& values) {
  const hsize_t dims[2] = {static_cast<hsize_t>(values.rows()), static_cast<hsize_t>(values.cols())};
  H5::DataSet ds = file_.createDataSet(dataset, H5::PredType::IEEE_F64LE, H5::DataSpace(2, dims));
  if (values.size() > 0) ds.write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

void Writer::commit() {
  try {
    file_.flush(H5F_SCOPE_GLOBAL);
    file_.close();
  } catch (const H5::Exception& e) {
    throw Error("cannot write '" + temp_path_ + "' (" + e.getDetailMsg() + ")");
  }
  std::error_code ec;
  std::filesystem::rename(temp_path_, path_, ec);
  if (ec) throw Error("cannot rename '" + temp_path_ + "' to '" + path_ + "': " + ec.message());
  committed_ = true;
}

}  // namespace mufric::h5
