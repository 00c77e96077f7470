#pragma once
// Thin, error-naming helpers over the HDF5 C++ API. Every failure becomes mufric::Error whose
// message names the file and the object ("model.h5: /gp/alpha: ...").
#include <H5Cpp.h>

#include <Eigen/Dense>
#include <functional>
#include <cstdint>
#include <string>
#include <vector>

namespace mufric::h5 {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Silences HDF5's own stderr traces; our messages replace them.
void quiet_hdf5_errors();

class Reader {
 public:
  // Throws Error if the file is missing, unreadable, truncated or not HDF5.
  Reader(const std::string& path, const std::string& what);
  const std::string& path() const { return path_; }

  bool has(const std::string& object) const;
  bool has_attribute(const std::string& object, const std::string& name) const;
  std::string string_attribute(const std::string& object, const std::string& name) const;
  double double_attribute(const std::string& object, const std::string& name) const;
  long long int_attribute(const std::string& object, const std::string& name) const;

  std::vector<double> doubles(const std::string& dataset) const;
  std::vector<long long> ints(const std::string& dataset) const;
  std::vector<std::string> strings(const std::string& dataset) const;
  RowMatrix matrix(const std::string& dataset) const;
  // Reads exactly `expected` values or throws naming the dataset and both sizes.
  Eigen::VectorXd vector(const std::string& dataset, Eigen::Index expected) const;

  // Refuses a file whose root attributes 'format' and 'schema_version' are not `format`, `version`.
  void require_format(const std::string& format, long long version, const std::string& kind_of_file) const;
  // Accepts schema versions oldest…newest; returns the file's.
  long long require_format(const std::string& format, long long oldest, long long newest, const std::string& kind_of_file) const;

  [[noreturn]] void fail(const std::string& object, const std::string& problem) const;

 private:
  H5::DataSet open_dataset(const std::string& dataset) const;
  // The number of values `dataset` declares, refused when the file is too small to hold them at
  // `min_bytes_per_value` each: a corrupt dataspace must not make us allocate terabytes.
  size_t value_count(const std::string& dataset, const H5::DataSet& ds, size_t min_bytes_per_value) const;
  H5::H5Object& object_for_attribute(const std::string& object, H5::Group& group_storage) const;
  // Opens an existing attribute of `object` whose type class is one of `classes`, or fails naming it.
  H5::Attribute open_attribute(const std::string& object, const std::string& name, std::initializer_list<H5T_class_t> classes,
                               const std::string& expected) const;
  // Runs an attribute read; an HDF5 exception from it becomes Error naming the object and attribute.
  void read_attribute(const std::string& object, const std::string& name, const std::function<void()>& read) const;
  std::string path_;
  std::string what_;
  std::uintmax_t file_bytes_ = 0;
  mutable H5::H5File file_;
};

class Writer {
 public:
  // Writes to `path`.tmp; commit() flushes and renames atomically over `path`, so a reader never
  // sees a half-written file. Destroying an uncommitted Writer removes the temporary.
  explicit Writer(const std::string& path);
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  void group(const std::string& name);
  void string_attribute(const std::string& object, const std::string& name, const std::string& value);
  void double_attribute(const std::string& object, const std::string& name, double value);
  void int_attribute(const std::string& object, const std::string& name, long long value);
  void doubles(const std::string& dataset, const std::vector<double>& values);
  void doubles(const std::string& dataset, const Eigen::VectorXd& values);
  void ints(const std::string& dataset, const std::vector<long long>& values);
  void strings(const std::string& dataset, const std::vector<std::string>& values);
  void matrix(const std::string& dataset, const RowMatrix& values);
  void commit();

 private:
  H5::H5Object& object(const std::string& name, H5::Group& storage);
  std::string path_;
  std::string temp_path_;
  H5::H5File file_;
  bool committed_ = false;
};

}  // namespace mufric::h5
