#include "io/artifact.h"

#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <optional>

#include "core/check.h"
#include "io/h5_probe.h"
#include "io/version.h"

namespace jvl::io {
namespace {

constexpr char kSchemaAttr[] = "schema";
constexpr char kVersionAttr[] = "schema_version";
constexpr char kProvenanceAttr[] = "provenance";

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

template <typename T>
hid_t NativeType();
template <>
hid_t NativeType<double>() {
  return H5T_NATIVE_DOUBLE;
}
template <>
hid_t NativeType<float>() {
  return H5T_NATIVE_FLOAT;
}
template <>
hid_t NativeType<int64_t>() {
  return H5T_NATIVE_INT64;
}
template <>
hid_t NativeType<int32_t>() {
  return H5T_NATIVE_INT32;
}
template <>
hid_t NativeType<uint8_t>() {
  return H5T_NATIVE_UINT8;
}

// Closes an HDF5 handle when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void SilenceHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

std::pair<std::string, std::string> SplitParent(const std::string& name) {
  const auto slash = name.find_last_of('/');
  if (slash == std::string::npos) return {"/", name};
  return {name.substr(0, slash), name.substr(slash + 1)};
}

bool LinkExists(hid_t file, const std::string& name) {
  // Check every prefix: H5Lexists fails if an intermediate group is missing.
  size_t pos = 0;
  while (true) {
    pos = name.find('/', pos + 1);
    const std::string prefix = name.substr(0, pos);
    if (!prefix.empty() && prefix != "/" && H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) {
      return false;
    }
    if (pos == std::string::npos) return true;
  }
}

void WriteStringAttribute(hid_t object, const std::string& name, const std::string& value,
                          const std::string& file) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<size_t>(1, value.size()));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  if (H5Aexists(object, name.c_str()) > 0) H5Adelete(object, name.c_str());
  Handle attr(H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  JVL_CHECK(attr.ok(), file << ": cannot create attribute '" << name << "'");
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  JVL_CHECK(H5Awrite(attr.get(), type.get(), padded.data()) >= 0,
            file << ": cannot write attribute '" << name << "'");
}

// Whether an attribute holds exactly one element (H5Aread writes every element into the buffer).
bool IsScalarAttribute(hid_t attr) {
  Handle space(H5Aget_space(attr), H5Sclose);
  return space.ok() && H5Sget_simple_extent_npoints(space.get()) == 1;
}

std::optional<std::string> ReadStringAttribute(hid_t object, const std::string& name) {
  if (H5Aexists(object, name.c_str()) <= 0) return std::nullopt;
  Handle attr(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!attr.ok() || !IsScalarAttribute(attr.get())) return std::nullopt;
  Handle type(H5Aget_type(attr.get()), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) > 0) {
    return std::nullopt;
  }
  const size_t size = H5Tget_size(type.get());
  if (size > (size_t{1} << 28)) return std::nullopt;  // A damaged type; no attribute is this big.
  std::string value(size, '\0');
  if (H5Aread(attr.get(), type.get(), value.data()) < 0) return std::nullopt;
  value.resize(std::strlen(value.c_str()));
  return value;
}

std::optional<int64_t> ReadIntAttribute(hid_t object, const std::string& name) {
  if (H5Aexists(object, name.c_str()) <= 0) return std::nullopt;
  Handle attr(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose);
  int64_t value = 0;
  if (!attr.ok() || !IsScalarAttribute(attr.get()) ||
      H5Aread(attr.get(), H5T_NATIVE_INT64, &value) < 0) {
    return std::nullopt;
  }
  return value;
}

}  // namespace

const std::vector<std::string>& ProvenanceTimeFields() {
  static const std::vector<std::string> kFields = {"created_utc", "wall_time_s",
                                                   "peak_memory_bytes"};
  return kFields;
}

nlohmann::json Provenance::ToJson() const {
  nlohmann::json j;
  j["tool"] = tool;
  j["version"] = JVL_VERSION;
  j["git_revision"] = JVL_GIT_REVISION;
  j["options"] = options;
  j["dataset_id"] = dataset_id;
  nlohmann::json in = nlohmann::json::array();
  for (const auto& f : inputs) in.push_back({{"path", f.path}, {"size", f.size}, {"hash", f.hash}});
  j["inputs"] = in;
  j["wall_time_s"] = wall_time_s;
  j["peak_memory_bytes"] = peak_memory_bytes;
  j["created_utc"] = UtcNow();
  return j;
}

// ---------------------------------------------------------------------------------------------
struct H5Writer::Impl {
  std::string path, tmp, schema;
  std::unique_ptr<PendingTempFile> pending;  // removes tmp on SIGINT/SIGTERM
  int version = 0;
  hid_t file = -1;
  bool committed = false;

  // Property lists that keep files byte-identical across runs (no object timestamps).
  hid_t GroupCreateProps() const {
    hid_t gcpl = H5Pcreate(H5P_GROUP_CREATE);
    H5Pset_obj_track_times(gcpl, 0);
    return gcpl;
  }

  void EnsureGroup(const std::string& group) {
    if (group.empty() || group == "/") return;
    size_t pos = 0;
    while (pos != std::string::npos) {
      pos = group.find('/', pos + 1);
      const std::string prefix = group.substr(0, pos);
      if (prefix.empty()) continue;
      if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) > 0) continue;
      Handle gcpl(GroupCreateProps(), H5Pclose);
      Handle g(H5Gcreate2(file, prefix.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose);
      JVL_CHECK(g.ok(), path << ": cannot create group '" << prefix << "'");
    }
  }
};

H5Writer::H5Writer(std::string path, std::string schema, int schema_version)
    : impl_(std::make_unique<Impl>()) {
  SilenceHdf5Errors();
  impl_->path = std::move(path);
  impl_->schema = std::move(schema);
  impl_->version = schema_version;
  const std::filesystem::path p(impl_->path);
  if (p.has_parent_path()) CreateDirectories(p.parent_path().string());
  impl_->tmp = TempPathFor(impl_->path);
  impl_->pending = std::make_unique<PendingTempFile>(impl_->tmp);
  Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_obj_track_times(fcpl.get(), 0);
  impl_->file = H5Fcreate(impl_->tmp.c_str(), H5F_ACC_TRUNC, fcpl.get(), H5P_DEFAULT);
  JVL_CHECK(impl_->file >= 0, impl_->tmp << ": cannot create HDF5 file");
  try {
    WriteStringAttribute(impl_->file, kSchemaAttr, impl_->schema, impl_->path);
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle attr(
        H5Acreate2(impl_->file, kVersionAttr, H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
        H5Aclose);
    const int64_t v = schema_version;
    JVL_CHECK(attr.ok() && H5Awrite(attr.get(), H5T_NATIVE_INT64, &v) >= 0,
              impl_->path << ": cannot write the schema version");
  } catch (...) {
    // No destructor runs for a constructor that throws: close and remove here.
    H5Fclose(impl_->file);
    impl_->file = -1;
    std::error_code ec;
    std::filesystem::remove(impl_->tmp, ec);
    throw;
  }
}

H5Writer::~H5Writer() {
  if (!impl_) return;
  if (impl_->file >= 0) H5Fclose(impl_->file);
  if (!impl_->committed) {
    std::error_code ec;
    std::filesystem::remove(impl_->tmp, ec);
  }
}

template <typename T>
void H5Writer::WriteArray(const std::string& name, const std::vector<T>& data,
                          std::vector<int64_t> dims) {
  if (dims.empty()) dims = {static_cast<int64_t>(data.size())};
  int64_t count = 1;
  for (int64_t d : dims) count *= d;
  JVL_CHECK(count == static_cast<int64_t>(data.size()),
            impl_->path << ": dataset '" << name << "' has " << data.size()
                        << " values but its shape holds " << count);
  const auto [parent, leaf] = SplitParent(name);
  impl_->EnsureGroup(parent);
  std::vector<hsize_t> hdims(dims.begin(), dims.end());
  Handle space(H5Screate_simple(static_cast<int>(hdims.size()), hdims.data(), nullptr), H5Sclose);
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(dcpl.get(), 0);
  if (count >= 4096 && dims[0] > 0) {
    // Chunk along rows, ~64k values per chunk; shuffle + deflate pays off for poses and points.
    std::vector<hsize_t> chunk = hdims;
    hsize_t row = 1;
    for (size_t i = 1; i < chunk.size(); ++i) row *= chunk[i];
    chunk[0] = std::max<hsize_t>(1, std::min<hsize_t>(hdims[0], 65536 / std::max<hsize_t>(1, row)));
    H5Pset_chunk(dcpl.get(), static_cast<int>(chunk.size()), chunk.data());
    H5Pset_shuffle(dcpl.get());
    H5Pset_deflate(dcpl.get(), 1);
  }
  Handle ds(H5Dcreate2(impl_->file, name.c_str(), NativeType<T>(), space.get(), H5P_DEFAULT,
                       dcpl.get(), H5P_DEFAULT),
            H5Dclose);
  JVL_CHECK(ds.ok(), impl_->path << ": cannot create dataset '" << name << "'");
  if (count > 0) {
    JVL_CHECK(H5Dwrite(ds.get(), NativeType<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) >= 0,
              impl_->path << ": cannot write dataset '" << name << "' (disk full?)");
  }
}

void H5Writer::WriteString(const std::string& name, const std::string& value) {
  const auto [parent, leaf] = SplitParent(name);
  if (parent == "/") {
    WriteStringAttribute(impl_->file, leaf, value, impl_->path);
    return;
  }
  impl_->EnsureGroup(parent);
  Handle obj(H5Oopen(impl_->file, parent.c_str(), H5P_DEFAULT), H5Oclose);
  JVL_CHECK(obj.ok(), impl_->path << ": cannot open '" << parent << "'");
  WriteStringAttribute(obj.get(), leaf, value, impl_->path);
}

void H5Writer::Commit(const Provenance& provenance) {
  JVL_CHECK(!impl_->committed, impl_->path << ": committed twice");
  WriteStringAttribute(impl_->file, kProvenanceAttr, provenance.ToJson().dump(), impl_->path);
  JVL_CHECK(H5Fflush(impl_->file, H5F_SCOPE_GLOBAL) >= 0, impl_->path << ": flush failed");
  const herr_t closed = H5Fclose(impl_->file);
  impl_->file = -1;
  JVL_CHECK(closed >= 0, impl_->path << ": closing the HDF5 file failed (disk full?)");
  std::error_code ec;
  std::filesystem::rename(impl_->tmp, impl_->path, ec);
  JVL_CHECK(!ec,
            impl_->path << ": cannot move the finished file into place (" << ec.message() << ")");
  impl_->committed = true;
}

template void H5Writer::WriteArray<double>(const std::string&, const std::vector<double>&,
                                           std::vector<int64_t>);
template void H5Writer::WriteArray<float>(const std::string&, const std::vector<float>&,
                                          std::vector<int64_t>);
template void H5Writer::WriteArray<int64_t>(const std::string&, const std::vector<int64_t>&,
                                            std::vector<int64_t>);
template void H5Writer::WriteArray<int32_t>(const std::string&, const std::vector<int32_t>&,
                                            std::vector<int64_t>);
template void H5Writer::WriteArray<uint8_t>(const std::string&, const std::vector<uint8_t>&,
                                            std::vector<int64_t>);

// ---------------------------------------------------------------------------------------------
struct H5Reader::Impl {
  std::string path, schema;
  int version = 0;
  hid_t file = -1;
};

H5Reader::H5Reader(std::string path, const std::string& schema, int schema_version)
    : impl_(std::make_unique<Impl>()) {
  SilenceHdf5Errors();
  impl_->path = std::move(path);
  const std::string& p = impl_->path;
  JVL_CHECK(FileExists(p), p << ": file not found");
  JVL_CHECK(H5Fis_hdf5(p.c_str()) > 0, p << ": not an HDF5 file (or truncated)");
  JVL_CHECK(Hdf5MetadataWalkSurvives(p),
            p << ": damaged HDF5 file (the HDF5 library crashes reading its metadata)");
  impl_->file = H5Fopen(p.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  JVL_CHECK(impl_->file >= 0, p << ": cannot open HDF5 file (truncated or damaged?)");
  try {
    CheckSchema(schema, schema_version);
  } catch (...) {
    // No destructor runs for a constructor that throws; a file left open would also make a
    // later open of the same path see this file's cached metadata.
    H5Fclose(impl_->file);
    impl_->file = -1;
    throw;
  }
}

void H5Reader::CheckSchema(const std::string& schema, int schema_version) {
  const std::string& p = impl_->path;
  const auto found_schema = ReadStringAttribute(impl_->file, kSchemaAttr);
  const auto found_version = ReadIntAttribute(impl_->file, kVersionAttr);
  JVL_CHECK(found_schema && found_version,
            p << ": not a jvl artifact (no schema attribute); expected schema '" << schema << "'");
  impl_->schema = *found_schema;
  impl_->version = static_cast<int>(*found_version);
  if (!schema.empty()) {
    JVL_CHECK(impl_->schema == schema && impl_->version == schema_version,
              p << ": expected schema '" << schema << "' version " << schema_version << ", found '"
                << impl_->schema << "' version " << impl_->version);
  }
}

H5Reader::~H5Reader() {
  if (impl_ && impl_->file >= 0) H5Fclose(impl_->file);
}

bool H5Reader::Has(const std::string& name) const { return LinkExists(impl_->file, name); }

std::vector<int64_t> H5Reader::Dims(const std::string& name) const {
  JVL_CHECK(Has(name), impl_->path << ": missing dataset '" << name << "'");
  Handle ds(H5Dopen2(impl_->file, name.c_str(), H5P_DEFAULT), H5Dclose);
  JVL_CHECK(ds.ok(), impl_->path << ": '" << name << "' is not a dataset");
  Handle space(H5Dget_space(ds.get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  JVL_CHECK(rank >= 0, impl_->path << ": cannot read the shape of '" << name << "'");
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return std::vector<int64_t>(dims.begin(), dims.end());
}

std::string H5Reader::DatasetType(const std::string& name) const {
  JVL_CHECK(Has(name), impl_->path << ": missing dataset '" << name << "'");
  Handle ds(H5Dopen2(impl_->file, name.c_str(), H5P_DEFAULT), H5Dclose);
  JVL_CHECK(ds.ok(), impl_->path << ": '" << name << "' is not a dataset");
  Handle type(H5Dget_type(ds.get()), H5Tclose);
  const size_t bits = 8 * H5Tget_size(type.get());
  switch (H5Tget_class(type.get())) {
    case H5T_FLOAT:
      return "float" + std::to_string(bits);
    case H5T_INTEGER:
      return (H5Tget_sign(type.get()) == H5T_SGN_NONE ? "uint" : "int") + std::to_string(bits);
    case H5T_STRING:
      return "string";
    default:
      return "other";
  }
}

namespace {
#if H5_VERSION_GE(1, 12, 0)
using ObjectInfo = H5O_info2_t;
#define JVL_H5_VISIT(file, op, data) \
  H5Ovisit3(file, H5_INDEX_NAME, H5_ITER_INC, op, data, H5O_INFO_BASIC)
#else
using ObjectInfo = H5O_info_t;
#define JVL_H5_VISIT(file, op, data) H5Ovisit(file, H5_INDEX_NAME, H5_ITER_INC, op, data)
#endif
herr_t CollectDataset(hid_t, const char* name, const ObjectInfo* info, void* data) {
  if (info->type == H5O_TYPE_DATASET) static_cast<std::vector<std::string>*>(data)->push_back(name);
  return 0;
}
herr_t CollectObject(hid_t, const char* name, const ObjectInfo*, void* data) {
  static_cast<std::vector<std::string>*>(data)->push_back(name);
  return 0;
}
herr_t CollectAttribute(hid_t, const char* name, const H5A_info_t*, void* data) {
  static_cast<std::vector<std::string>*>(data)->push_back(name);
  return 0;
}
}  // namespace

std::vector<std::string> H5Reader::ListDatasets() const {
  std::vector<std::string> names;
  JVL_H5_VISIT(impl_->file, CollectDataset, &names);
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::string> H5Reader::ListAttributes() const {
  std::vector<std::string> objects, names;
  JVL_H5_VISIT(impl_->file, CollectObject, &objects);  // "." is the root.
  for (const std::string& object : objects) {
    Handle obj(H5Oopen(impl_->file, object.c_str(), H5P_DEFAULT), H5Oclose);
    JVL_CHECK(obj.ok(), impl_->path << ": cannot open '" << object << "'");
    std::vector<std::string> attrs;
    hsize_t index = 0;
    H5Aiterate2(obj.get(), H5_INDEX_NAME, H5_ITER_INC, &index, CollectAttribute, &attrs);
    for (const std::string& a : attrs) names.push_back(object == "." ? a : object + "/" + a);
  }
  std::sort(names.begin(), names.end());
  return names;
}

namespace {

// Unchunked data is stored whole: a damaged header can declare fewer stored bytes than the
// shape's `count` values need, and libhdf5 then copies from a missing buffer (a crash, found by
// the artifact fuzzer) instead of failing. Chunked data may be compressed, so its size says
// nothing.
void CheckStoredWhole(hid_t ds, int64_t count, const std::string& path, const std::string& name) {
  Handle plist(H5Dget_create_plist(ds), H5Pclose);
  Handle type(H5Dget_type(ds), H5Tclose);
  JVL_CHECK(plist.ok() && type.ok(),
            path << ": cannot read the layout of dataset '" << name << "' (damaged file?)");
  const H5D_layout_t layout = H5Pget_layout(plist.get());
  JVL_CHECK(layout == H5D_CONTIGUOUS || layout == H5D_CHUNKED || layout == H5D_COMPACT,
            path << ": dataset '" << name << "' has an unknown storage layout (damaged file?)");
  if (layout == H5D_CHUNKED) return;
  const uint64_t stored = H5Dget_storage_size(ds);
  const uint64_t needed = static_cast<uint64_t>(count) * H5Tget_size(type.get());
  JVL_CHECK(stored == needed, path << ": dataset '" << name << "' stores " << stored
                                   << " bytes for " << count << " values of "
                                   << H5Tget_size(type.get()) << " bytes (damaged file?)");
}

}  // namespace

template <typename T>
std::vector<T> H5Reader::ReadArray(const std::string& name, int64_t expected_cols) const {
  const auto dims = Dims(name);
  if (expected_cols > 0) {
    JVL_CHECK(dims.size() == 2 && dims[1] == expected_cols,
              impl_->path << ": dataset '" << name << "' should be N x " << expected_cols);
  }
  // A damaged file can declare any shape. A real one stores every value (no fill values), at
  // most ~1032 per byte with deflate, so larger shapes are rejected before allocating.
  const int64_t limit = 1100 * (FileSize(impl_->path) + 4096);
  int64_t count = 1;
  for (int64_t d : dims) {
    JVL_CHECK(d == 0 || count <= limit / d,
              impl_->path << ": dataset '" << name
                          << "' declares more values than the file can hold (damaged file?)");
    count *= d;
  }
  std::vector<T> out(static_cast<size_t>(count));
  if (count == 0) return out;
  Handle ds(H5Dopen2(impl_->file, name.c_str(), H5P_DEFAULT), H5Dclose);
  JVL_CHECK(ds.ok(), impl_->path << ": cannot open dataset '" << name << "' (damaged file?)");
  CheckStoredWhole(ds.get(), count, impl_->path, name);
  JVL_CHECK(H5Dread(ds.get(), NativeType<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) >= 0,
            impl_->path << ": cannot read dataset '" << name << "' (damaged file?)");
  return out;
}

template <typename T>
std::vector<T> H5Reader::ReadRows(const std::string& name,
                                  const std::vector<std::pair<int64_t, int64_t>>& ranges,
                                  int64_t expected_cols) const {
  const auto dims = Dims(name);
  JVL_CHECK(!dims.empty() && dims.size() <= 2,
            impl_->path << ": dataset '" << name << "' is not a 1-D or 2-D array");
  if (expected_cols > 0) {
    JVL_CHECK(dims.size() == 2 && dims[1] == expected_cols,
              impl_->path << ": dataset '" << name << "' should be N x " << expected_cols);
  }
  const int64_t cols = dims.size() == 2 ? dims[1] : 1;
  int64_t rows = 0, end = 0;
  for (const auto& [first, last] : ranges) {
    JVL_CHECK(first >= end && first <= last && last <= dims[0],
              impl_->path << ": rows [" << first << ", " << last << ") of dataset '" << name
                          << "' (" << dims[0] << " rows) are out of order or out of range");
    rows += last - first;
    end = last;
  }
  std::vector<T> out(static_cast<size_t>(rows * cols));
  if (out.empty()) return out;
  Handle ds(H5Dopen2(impl_->file, name.c_str(), H5P_DEFAULT), H5Dclose);
  JVL_CHECK(ds.ok(), impl_->path << ": cannot open dataset '" << name << "' (damaged file?)");
  CheckStoredWhole(ds.get(), dims[0] * cols, impl_->path, name);
  Handle file_space(H5Dget_space(ds.get()), H5Sclose);
  JVL_CHECK(file_space.ok(), impl_->path << ": cannot read the shape of '" << name << "'");
  size_t offset = 0;
  for (const auto& [first, last] : ranges) {
    if (first == last) continue;
    const hsize_t start[2] = {static_cast<hsize_t>(first), 0};
    const hsize_t count[2] = {static_cast<hsize_t>(last - first), static_cast<hsize_t>(cols)};
    const int rank = static_cast<int>(dims.size());
    Handle memory(H5Screate_simple(rank, count, nullptr), H5Sclose);
    JVL_CHECK(memory.ok() && H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr,
                                                 count, nullptr) >= 0,
              impl_->path << ": cannot select rows of dataset '" << name << "'");
    JVL_CHECK(H5Dread(ds.get(), NativeType<T>(), memory.get(), file_space.get(), H5P_DEFAULT,
                      out.data() + offset) >= 0,
              impl_->path << ": cannot read dataset '" << name << "' (damaged file?)");
    offset += static_cast<size_t>((last - first) * cols);
  }
  return out;
}

template std::vector<double> H5Reader::ReadArray<double>(const std::string&, int64_t) const;
template std::vector<float> H5Reader::ReadArray<float>(const std::string&, int64_t) const;
template std::vector<int64_t> H5Reader::ReadArray<int64_t>(const std::string&, int64_t) const;
template std::vector<int32_t> H5Reader::ReadArray<int32_t>(const std::string&, int64_t) const;
template std::vector<uint8_t> H5Reader::ReadArray<uint8_t>(const std::string&, int64_t) const;
#define JVL_READ_ROWS(T)                         \
  template std::vector<T> H5Reader::ReadRows<T>( \
      const std::string&, const std::vector<std::pair<int64_t, int64_t>>&, int64_t) const;
JVL_READ_ROWS(double)
JVL_READ_ROWS(float)
JVL_READ_ROWS(int64_t)
JVL_READ_ROWS(int32_t)
JVL_READ_ROWS(uint8_t)
#undef JVL_READ_ROWS

std::string H5Reader::ReadString(const std::string& name) const {
  const auto [parent, leaf] = SplitParent(name);
  std::optional<std::string> value;
  if (parent == "/") {
    value = ReadStringAttribute(impl_->file, leaf);
  } else if (Has(parent)) {
    Handle obj(H5Oopen(impl_->file, parent.c_str(), H5P_DEFAULT), H5Oclose);
    if (obj.ok()) value = ReadStringAttribute(obj.get(), leaf);
  }
  JVL_CHECK(value, impl_->path << ": missing string attribute '" << name << "'");
  return *value;
}

nlohmann::json H5Reader::ReadJson(const std::string& name) const {
  const std::string text = ReadString(name);
  try {
    return nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    JVL_THROW(impl_->path << ": attribute '" << name << "' is not valid JSON");
  }
}

std::string H5Reader::schema() const { return impl_->schema; }
int H5Reader::schema_version() const { return impl_->version; }
const std::string& H5Reader::path() const { return impl_->path; }
nlohmann::json H5Reader::provenance() const {
  const auto text = ReadStringAttribute(impl_->file, kProvenanceAttr);
  if (!text) return nlohmann::json::object();
  try {
    return nlohmann::json::parse(*text);
  } catch (const std::exception&) {
    return nlohmann::json::object();
  }
}

// ---------------------------------------------------------------------------------------------
std::string ReadArtifactDatasetId(const std::string& path) {
  SilenceHdf5Errors();
  nlohmann::json provenance;
  if (H5Fis_hdf5(path.c_str()) > 0) {
    try {
      provenance = H5Reader(path, "", 0).provenance();
    } catch (const Error&) {
      return "";  // Not a jvl artifact: its reader reports that.
    }
  } else if (path.size() > 5 && path.compare(path.size() - 5, 5, ".json") == 0) {
    try {
      const nlohmann::json j = nlohmann::json::parse(ReadTextFile(path));
      if (j.is_object() && j.contains("provenance")) provenance = j["provenance"];
    } catch (const std::exception&) {
      return "";
    }
  }
  if (!provenance.is_object() || !provenance.contains("dataset_id")) return "";
  const nlohmann::json& id = provenance["dataset_id"];
  return id.is_string() ? id.get<std::string>() : "";
}

void WriteJsonArtifact(const std::string& path, const std::string& schema, int schema_version,
                       const nlohmann::json& body, const Provenance& provenance) {
  nlohmann::json j = nlohmann::json::object();
  j["schema"] = schema;
  j["schema_version"] = schema_version;
  j["provenance"] = provenance.ToJson();
  for (auto it = body.begin(); it != body.end(); ++it) j[it.key()] = it.value();
  WriteTextFileAtomic(path, j.dump(2) + "\n");
}

std::string JsonErrorText(const std::exception& e) {
  std::string text = e.what();
  if (text.rfind("[json.exception.", 0) == 0) {
    const size_t end = text.find("] ");
    if (end != std::string::npos) text.erase(0, end + 2);
  }
  return text;
}

nlohmann::json ReadJsonArtifact(const std::string& path, const std::string& schema,
                                int schema_version) {
  JVL_CHECK(FileExists(path), path << ": file not found");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ReadTextFile(path));
  } catch (const nlohmann::json::exception& e) {
    JVL_THROW(path << ": not valid JSON (truncated?): " << JsonErrorText(e));
  }
  JVL_CHECK(j.is_object() && j.contains("schema") && j.contains("schema_version"),
            path << ": not a jvl artifact (no schema field); expected schema '" << schema << "'");
  const std::string found = j["schema"].is_string() ? j["schema"].get<std::string>() : "?";
  const int found_version =
      j["schema_version"].is_number_integer() ? j["schema_version"].get<int>() : -1;
  JVL_CHECK(found == schema && found_version == schema_version,
            path << ": expected schema '" << schema << "' version " << schema_version << ", found '"
                 << found << "' version " << found_version);
  return j;
}

}  // namespace jvl::io
