// Artifacts: HDF5 files (large arrays) and JSON files (small, human-readable) that carry a
// schema name + version and the provenance of the run that wrote them. See schemas/.
//
//   H5Writer w("odom.h5", "trajectory", 1);
//   w.WriteArray("trajectory/frames", frames);           // std::vector<int64_t>
//   w.WriteArray("trajectory/poses", poses, {n, 7});     // row-major
//   w.Commit(provenance);                                // atomic rename
//
//   H5Reader r("odom.h5", "trajectory", 1);              // throws naming file/expected/found
//   auto frames = r.ReadArray<int64_t>("trajectory/frames");
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "io/files.h"

namespace jvl::io {

struct Provenance {
  std::string tool;                                   // e.g. "lidar_odom"
  nlohmann::json options = nlohmann::json::object();  // Every option with its value.
  std::vector<FileInfo> inputs;
  std::string dataset_id;  // Identifies the sequence (see Dataset::id()).
  double wall_time_s = 0;
  int64_t peak_memory_bytes = 0;
  // Adds version, git revision and the UTC creation time.
  nlohmann::json ToJson() const;
};

// Fields of provenance that change from run to run (excluded from determinism checks).
const std::vector<std::string>& ProvenanceTimeFields();

class H5Writer {
 public:
  H5Writer(std::string path, std::string schema, int schema_version);
  ~H5Writer();  // Removes the temporary file if Commit() was not called.
  H5Writer(const H5Writer&) = delete;
  H5Writer& operator=(const H5Writer&) = delete;

  // Writes a dataset; `name` may contain groups ("a/b/c"), created on demand. dims defaults to
  // {data.size()}; the product of dims must equal data.size(). Supported T: double, float,
  // int64_t, int32_t, uint8_t.
  template <typename T>
  void WriteArray(const std::string& name, const std::vector<T>& data,
                  std::vector<int64_t> dims = {});
  // A string attribute on the root (or on a group/dataset given as "path@attr").
  void WriteString(const std::string& name, const std::string& value);
  void WriteJson(const std::string& name, const nlohmann::json& value) {
    WriteString(name, value.dump());
  }
  // Writes provenance, closes and renames the temporary file to the final path.
  void Commit(const Provenance& provenance);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class H5Reader {
 public:
  // Opens and checks the schema name and version (throws naming file, expected and found).
  // schema "" accepts any jvl artifact.
  H5Reader(std::string path, const std::string& schema, int schema_version);
  ~H5Reader();
  H5Reader(const H5Reader&) = delete;
  H5Reader& operator=(const H5Reader&) = delete;

  bool Has(const std::string& name) const;
  std::vector<int64_t> Dims(const std::string& name) const;
  // "float64", "float32", "int64", "int32", "uint8", ... of a dataset.
  std::string DatasetType(const std::string& name) const;
  // Names of all datasets ("group/name"), sorted.
  std::vector<std::string> ListDatasets() const;
  // Names of all attributes as ReadString takes them ("attr" on the root, "group/attr" on a group
  // or dataset), sorted.
  std::vector<std::string> ListAttributes() const;
  // Reads a dataset converting to T; `expected_cols` > 0 checks a 2-D shape (N x cols).
  template <typename T>
  std::vector<T> ReadArray(const std::string& name, int64_t expected_cols = 0) const;
  // Reads only the rows [first, last) of each of `ranges` (ascending, not overlapping, within the
  // dataset) one after another: the chunks no range touches are not decompressed.
  template <typename T>
  std::vector<T> ReadRows(const std::string& name,
                          const std::vector<std::pair<int64_t, int64_t>>& ranges,
                          int64_t expected_cols = 0) const;
  std::string ReadString(const std::string& name) const;
  nlohmann::json ReadJson(const std::string& name) const;
  std::string schema() const;
  int schema_version() const;
  nlohmann::json provenance() const;
  const std::string& path() const;

 private:
  void CheckSchema(const std::string& schema, int schema_version);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The dataset id in the provenance of an HDF5 or JSON artifact; "" for other files (trajectory
// text) and artifacts without one.
std::string ReadArtifactDatasetId(const std::string& path);

// The message of a JSON library error without the library's "[json.exception.<id>] " prefix,
// e.g. "parse error at line 1, column 5: syntax error ...".
std::string JsonErrorText(const std::exception& e);

// JSON artifacts: {"schema": ..., "schema_version": ..., "provenance": {...}, ...body}.
void WriteJsonArtifact(const std::string& path, const std::string& schema, int schema_version,
                       const nlohmann::json& body, const Provenance& provenance);
nlohmann::json ReadJsonArtifact(const std::string& path, const std::string& schema,
                                int schema_version);

}  // namespace jvl::io
