#include "golden.h"

#include <fnmatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "core/check.h"
#include "core/hash.h"
#include "core/strings.h"
#include "io/artifact.h"
#include "io/files.h"
#include "io/kitti.h"

namespace jvl::golden {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Names excluded by rule anywhere: measured run times and the thread count (a run setting that
// does not change any result).
bool Excluded(const std::string& name) {
  const std::string leaf = name.substr(name.find_last_of('/') + 1);
  return EndsWith(leaf, "_ms") || EndsWith(leaf, "time_s") || leaf == "threads" ||
         leaf == "provenance";
}

// A string that names a file (a path, or a name with a file extension): run-specific, so only
// its presence is compared.
bool IsPath(const std::string& s) {
  if (s.find('/') != std::string::npos) return true;
  for (const char* ext : {".h5", ".txt", ".json", ".csv", ".png", ".bin", ".ply", ".md"})
    if (EndsWith(s, ext)) return true;
  return false;
}

json Clean(const json& j) {
  if (j.is_string() && IsPath(j.get<std::string>())) return "<path>";
  if (j.is_object()) {
    json out = json::object();
    for (auto it = j.begin(); it != j.end(); ++it)
      if (!Excluded(it.key())) out[it.key()] = Clean(it.value());
    return out;
  }
  if (j.is_array()) {
    json out = json::array();
    for (const auto& v : j) out.push_back(Clean(v));
    return out;
  }
  return j;
}

// Row indices of the sample: evenly spread, first and last included.
std::vector<int64_t> SampleRows(int64_t rows) {
  std::vector<int64_t> out;
  if (rows <= kSampleRows) {
    for (int64_t r = 0; r < rows; ++r) out.push_back(r);
    return out;
  }
  for (int k = 0; k < kSampleRows; ++k) out.push_back(k * (rows - 1) / (kSampleRows - 1));
  return out;
}

// A numeric field: `values` row-major with `cols` columns.
template <typename T>
json NumericField(const std::vector<T>& values, int64_t cols, const std::vector<int64_t>& shape,
                  const std::vector<int64_t>* ids, const std::vector<std::string>& columns) {
  const bool integer = std::is_integral<T>::value;
  json f;
  f["kind"] = integer ? "int" : "float";
  f["shape"] = shape;
  if (!columns.empty()) f["columns"] = columns;
  const int64_t rows = cols > 0 ? static_cast<int64_t>(values.size()) / cols : 0;
  const std::vector<int64_t> sample = SampleRows(rows);
  f["rows"] = sample;
  if (ids != nullptr && static_cast<int64_t>(ids->size()) == rows) {
    json sampled_ids = json::array();
    for (int64_t r : sample) sampled_ids.push_back((*ids)[static_cast<size_t>(r)]);
    f["ids"] = sampled_ids;
  }
  json rows_json = json::array();
  for (int64_t r : sample) {
    json row = json::array();
    for (int64_t c = 0; c < cols; ++c) row.push_back(values[static_cast<size_t>(r * cols + c)]);
    rows_json.push_back(row);
  }
  f["values"] = rows_json;
  if (integer) {
    std::vector<int64_t> sums(static_cast<size_t>(std::max<int64_t>(cols, 0)), 0);
    Fnv1a64 hash;
    for (size_t i = 0; i < values.size(); ++i) {
      const int64_t v = static_cast<int64_t>(values[i]);
      sums[i % static_cast<size_t>(cols)] += v;
      hash.Update(&v, sizeof(v));
    }
    f["sums"] = sums;
    f["hash"] = hash.Hex();
  } else {
    std::vector<double> sums(static_cast<size_t>(std::max<int64_t>(cols, 0)), 0.0);
    for (size_t i = 0; i < values.size(); ++i) {
      const double v = static_cast<double>(values[i]);
      if (std::isfinite(v)) sums[i % static_cast<size_t>(cols)] += v;
    }
    f["sums"] = sums;
  }
  return f;
}

std::vector<std::string> PoseColumns(int64_t cols) {
  if (cols == 7) return {"qx", "qy", "qz", "qw", "tx", "ty", "tz"};
  if (cols == 12) return {"r00", "r01", "r02", "tx", "r10", "r11", "r12", "ty", "r20", "r21", "r22", "tz"};
  if (cols == 13)
    return {"frame", "r00", "r01", "r02", "tx", "r10", "r11", "r12", "ty", "r20", "r21", "r22", "tz"};
  return {};
}

void DigestH5(const std::string& path, json* digest) {
  const io::H5Reader r(path, "", 0);
  (*digest)["schema"] = r.schema();
  (*digest)["schema_version"] = r.schema_version();
  json& fields = (*digest)["fields"];
  for (const std::string& name : r.ListDatasets()) {
    if (Excluded(name)) continue;
    const std::vector<int64_t> dims = r.Dims(name);
    int64_t cols = 1;
    for (size_t i = 1; i < dims.size(); ++i) cols *= dims[i];
    // Rows labelled by the frame ids of their group (trajectory/frames, keyframes/frames), or of
    // the trajectory when the group has none and the row counts agree (odometry diagnostics).
    const std::string group = name.substr(0, name.find_last_of('/') + 1);
    std::vector<int64_t> ids;
    bool has_ids = false;
    for (const std::string& frames : {group + "frames", std::string("trajectory/frames")}) {
      if (has_ids || group.empty() || name == frames || !r.Has(frames) || dims.empty()) continue;
      if (r.Dims(frames) != std::vector<int64_t>{dims[0]}) continue;
      ids = r.ReadArray<int64_t>(frames);
      has_ids = true;
    }
    const std::string leaf = name.substr(group.size());
    const std::vector<std::string> columns =
        leaf == "poses" || leaf == "position" ? PoseColumns(cols) : std::vector<std::string>{};
    if (r.DatasetType(name).rfind("float", 0) == 0) {
      fields[name] = NumericField(r.ReadArray<double>(name), cols, dims, has_ids ? &ids : nullptr,
                                  columns);
    } else {
      fields[name] = NumericField(r.ReadArray<int64_t>(name), cols, dims, has_ids ? &ids : nullptr,
                                  columns);
    }
  }
  for (const std::string& name : r.ListAttributes()) {
    if (name == "schema" || name == "schema_version" || Excluded(name)) continue;
    const std::string text = r.ReadString(name);
    const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
    json f;
    if (!j.is_discarded() && j.is_structured()) {
      f["kind"] = "json";
      f["value"] = Clean(j);
    } else {
      f["kind"] = "string";
      f["value"] = text;
    }
    fields["@" + name] = f;
  }
}

// Numeric text: KITTI poses, times, CSV with or without a header. Non-numeric cells (a CSV's
// labels) are kept as a hash of their text; their numeric columns hold NaN.
json TextField(const std::string& path) {
  std::istringstream in(io::ReadTextFile(path));
  std::string line;
  std::vector<std::string> header;
  std::vector<double> values;
  int64_t cols = -1;
  Fnv1a64 labels;
  bool first = true;
  while (std::getline(in, line)) {
    const auto tokens = SplitWhitespace(line, /*comma=*/true);
    if (tokens.empty()) continue;
    bool numeric = false;
    for (const auto& t : tokens) numeric |= ParseDouble(t).has_value();
    if (first && !numeric) {
      for (const auto& t : tokens) header.emplace_back(t);
      first = false;
      continue;
    }
    first = false;
    JVL_CHECK(cols < 0 || static_cast<int64_t>(tokens.size()) == cols,
              path << ": rows of different lengths");
    cols = static_cast<int64_t>(tokens.size());
    for (const auto& t : tokens) {
      const auto v = ParseDouble(t);
      if (v) {
        values.push_back(*v);
      } else {
        values.push_back(std::nan(""));
        labels.Update(t.data(), t.size());
      }
    }
  }
  if (cols < 0) cols = 0;
  const std::vector<int64_t> shape = {cols > 0 ? static_cast<int64_t>(values.size()) / cols : 0,
                                      cols};
  json f = NumericField(values, cols, shape, nullptr,
                        header.empty() ? PoseColumns(cols) : header);
  f["labels_hash"] = labels.Hex();
  return f;
}

json ScanField(const std::string& path) {
  const PointCloud cloud = io::ReadVelodyneBin(path);
  std::vector<double> values;
  values.reserve(cloud.size() * 4);
  for (size_t i = 0; i < cloud.size(); ++i) {
    values.push_back(cloud.points[i].x());
    values.push_back(cloud.points[i].y());
    values.push_back(cloud.points[i].z());
    values.push_back(cloud.intensity.empty() ? 0.0 : cloud.intensity[i]);
  }
  return NumericField(values, 4, {static_cast<int64_t>(cloud.size()), 4}, nullptr,
                      {"x", "y", "z", "reflectance"});
}

json ImageField(const std::string& path) {
  const cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  JVL_CHECK(!image.empty(), path << ": image does not decode");
  cv::Scalar mean, std;
  cv::meanStdDev(image, mean, std);
  Fnv1a64 hash;
  for (int r = 0; r < image.rows; ++r)
    hash.Update(image.ptr(r), static_cast<size_t>(image.cols) * image.elemSize());
  json f;
  f["kind"] = "image";
  f["size"] = {image.cols, image.rows, image.channels()};
  f["mean"] = mean[0];
  f["std"] = std[0];
  f["hash"] = hash.Hex();
  return f;
}

void DigestFile(const std::string& path, const std::string& field_prefix, json* fields) {
  if (EndsWith(path, ".h5")) {
    json sub;
    DigestH5(path, &sub);
    for (auto it = sub["fields"].begin(); it != sub["fields"].end(); ++it)
      (*fields)[field_prefix + it.key()] = it.value();
  } else if (EndsWith(path, ".json")) {
    json j;
    try {
      j = json::parse(io::ReadTextFile(path));
    } catch (const json::exception& e) {
      JVL_THROW(path << ": not valid JSON: " << io::JsonErrorText(e));
    }
    (*fields)[field_prefix + "body"] = {{"kind", "json"}, {"value", Clean(j)}};
  } else if (EndsWith(path, ".txt") || EndsWith(path, ".csv")) {
    (*fields)[field_prefix.empty() ? "rows" : field_prefix] = TextField(path);
  } else if (EndsWith(path, ".bin")) {
    (*fields)[field_prefix.empty() ? "points" : field_prefix] = ScanField(path);
  } else if (EndsWith(path, ".png")) {
    (*fields)[field_prefix.empty() ? "pixels" : field_prefix] = ImageField(path);
  }
}

std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.10g", v);
  return buf;
}

class Comparer {
 public:
  Comparer(const std::string& artifact, const Tolerances& tolerances, Comparison* out)
      : artifact_(artifact), tolerances_(tolerances), out_(out) {}

  void Add(const std::string& field, const std::string& where, const std::string& expected,
           const std::string& found, double diff = 0, Tolerance tolerance = {}) {
    out_->differences.push_back({field, where, expected, found, diff, tolerance});
  }

  // `key`: the name the tolerance rules see (the field, or field + JSON path).
  void Number(const std::string& field, const std::string& where, double e, double f,
              double scale = 1.0, const std::string& key = "") {
    ++out_->values_compared;
    if ((std::isnan(e) && std::isnan(f)) || e == f) return;
    Tolerance t = tolerances_.For(artifact_, key.empty() ? field : key);
    t.abs *= scale;
    const double diff = std::abs(f - e);
    if (std::isfinite(diff) && diff <= t.abs + t.rel * std::max(std::abs(e), std::abs(f))) return;
    Add(field, where, Num(e), Num(f), diff, t);
  }

  void Json(const std::string& field, const std::string& where, const json& e, const json& f) {
    const std::string path_field = field + where;
    if (e.is_number() && f.is_number()) {
      if (e.is_number_integer() && f.is_number_integer()) {
        ++out_->values_compared;
        if (e != f) Add(field, where, e.dump(), f.dump());
      } else {
        Number(field, where, e.get<double>(), f.get<double>(), 1.0, path_field);
      }
      return;
    }
    if (e.type() != f.type()) return Add(field, where, e.dump(), f.dump());
    if (e.is_object()) {
      for (auto it = e.begin(); it != e.end(); ++it) {
        if (!f.contains(it.key())) {
          Add(field, where + "/" + it.key(), it.value().dump(), "(missing)");
        } else {
          Json(field, where + "/" + it.key(), it.value(), f[it.key()]);
        }
      }
      for (auto it = f.begin(); it != f.end(); ++it)
        if (!e.contains(it.key())) Add(field, where + "/" + it.key(), "(missing)", it.value().dump());
    } else if (e.is_array()) {
      if (e.size() != f.size()) {
        return Add(field, where, std::to_string(e.size()) + " elements",
                   std::to_string(f.size()) + " elements");
      }
      for (size_t i = 0; i < e.size(); ++i)
        Json(field, where + "[" + std::to_string(i) + "]", e[i], f[i]);
    } else {
      ++out_->values_compared;
      if (e != f) Add(field, where, e.dump(), f.dump());
    }
  }

  // Row label: the frame / keyframe id where the artifact has one, else the row index.
  static std::string RowLabel(const json& field, size_t k) {
    if (field.contains("ids")) return "frame " + field["ids"][k].dump();
    return "row " + field["rows"][k].dump();
  }
  static std::string ColumnLabel(const json& field, size_t c) {
    if (field.contains("columns") && c < field["columns"].size())
      return field["columns"][c].get<std::string>();
    return "column " + std::to_string(c);
  }

  void NumericField(const std::string& name, const json& e, const json& f) {
    if (e["shape"] != f["shape"])
      return Add(name, "shape", e["shape"].dump(), f["shape"].dump());
    if (e["kind"] != f["kind"]) return Add(name, "type", e["kind"].dump(), f["kind"].dump());
    if (e.contains("ids") && e["ids"] != f.value("ids", json())) {
      return Add(name, "ids of the sampled rows", e["ids"].dump(),
                 f.value("ids", json()).dump());
    }
    const bool integer = e["kind"] == "int";
    const size_t before = out_->differences.size();
    for (size_t k = 0; k < e["values"].size(); ++k) {
      const json& re = e["values"][k];
      const json& rf = f["values"][k];
      for (size_t c = 0; c < re.size(); ++c) {
        const std::string where = RowLabel(e, k) + ", " + ColumnLabel(e, c);
        if (integer) {
          ++out_->values_compared;
          if (re[c] != rf[c]) Add(name, where, re[c].dump(), rf[c].dump());
        } else {
          Number(name, where, ToDouble(re[c]), ToDouble(rf[c]));
        }
      }
    }
    // Column sums over all rows: a change outside the sample shows here.
    const double rows = e["shape"].empty() ? 0.0 : e["shape"][0].get<double>();
    for (size_t c = 0; c < e["sums"].size(); ++c) {
      const std::string where = "sum over all rows, " + ColumnLabel(e, c);
      if (integer) {
        ++out_->values_compared;
        if (e["sums"][c] != f["sums"][c]) Add(name, where, e["sums"][c].dump(), f["sums"][c].dump());
      } else {
        Number(name, where, ToDouble(e["sums"][c]), ToDouble(f["sums"][c]), std::max(1.0, rows));
      }
    }
    if (integer && e.value("hash", "") != f.value("hash", "") &&
        out_->differences.size() == before) {
      Add(name, "hash of all values (a row outside the sample changed)", e["hash"].dump(),
          f["hash"].dump());
    }
    if (e.contains("labels_hash") && e["labels_hash"] != f.value("labels_hash", json()))
      Add(name, "text labels", e["labels_hash"].dump(), f.value("labels_hash", json()).dump());
  }

  void Field(const std::string& name, const json& e, const json& f) {
    const std::string kind = e.value("kind", "");
    if (kind != f.value("kind", "")) return Add(name, "kind", kind, f.value("kind", ""));
    if (kind == "int" || kind == "float") return NumericField(name, e, f);
    if (kind == "json") return Json(name, "", e["value"], f["value"]);
    if (kind == "image") {
      if (e["size"] != f["size"]) return Add(name, "size", e["size"].dump(), f["size"].dump());
      Number(name, "mean", e["mean"], f["mean"]);
      Number(name, "std", e["std"], f["std"]);
      const Tolerance t = tolerances_.For(artifact_, name);
      ++out_->values_compared;
      if (e["hash"] != f["hash"] && t.abs == 0 && t.rel == 0)
        Add(name, "pixels (hash)", e["hash"].dump(), f["hash"].dump());
      return;
    }
    ++out_->values_compared;
    if (e != f) Add(name, "value", e.dump(), f.dump());
  }

  static double ToDouble(const json& v) {
    return v.is_null() ? std::nan("") : v.get<double>();  // NaN is stored as null
  }

 private:
  std::string artifact_;
  const Tolerances& tolerances_;
  Comparison* out_;
};

}  // namespace

json Digest(const std::string& path, const std::string& name) {
  json digest;
  digest["artifact"] = name;
  digest["fields"] = json::object();
  if (io::IsDirectory(path)) {
    digest["kind"] = "folder";
    std::vector<std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(path)) {
      if (!e.is_regular_file()) continue;
      const std::string rel = fs::relative(e.path(), path).string();
      if (rel.find(".tmp.") != std::string::npos) continue;
      files.push_back(rel);
    }
    std::sort(files.begin(), files.end());
    for (const std::string& rel : files)
      DigestFile((fs::path(path) / rel).string(), rel + (EndsWith(rel, ".h5") ? ":" : ""),
                 &digest["fields"]);
    return digest;
  }
  JVL_CHECK(io::FileExists(path), path << ": file not found");
  digest["kind"] = "file";
  if (EndsWith(path, ".h5")) {
    DigestH5(path, &digest);
  } else {
    DigestFile(path, "", &digest["fields"]);
  }
  return digest;
}

Tolerances Tolerances::Load(const std::string& path) {
  Tolerances t;
  json rules;
  try {
    rules = json::parse(io::ReadTextFile(path));
  } catch (const json::exception& e) {
    JVL_THROW(path << ": not valid JSON: " << io::JsonErrorText(e));
  }
  JVL_CHECK(rules.is_object() && rules.contains("rules") && rules["rules"].is_array(),
            path << ": expected {\"rules\": [...]}");
  for (const auto& r : rules["rules"]) {
    JVL_CHECK(r.contains("match") && r.contains("why"), path << ": a rule lacks match or why");
    t.rules_.push_back({r["match"].get<std::string>(),
                        {r.value("abs", 0.0), r.value("rel", 0.0), r["why"].get<std::string>()}});
  }
  return t;
}

Tolerance Tolerances::For(const std::string& artifact, const std::string& field) const {
  const std::string key = artifact + ":" + field;
  for (const Rule& r : rules_)
    if (fnmatch(r.match.c_str(), key.c_str(), 0) == 0) return r.tolerance;
  return {};
}

Comparison Compare(const json& expected, const json& found, const Tolerances& tolerances) {
  Comparison out;
  const std::string artifact = expected.value("artifact", "?");
  Comparer c(artifact, tolerances, &out);
  for (const char* key : {"schema", "schema_version"}) {
    if (expected.value(key, json()) != found.value(key, json()))
      c.Add(key, "", expected.value(key, json()).dump(), found.value(key, json()).dump());
  }
  const json& e = expected["fields"];
  const json& f = found["fields"];
  for (auto it = e.begin(); it != e.end(); ++it) {
    if (!f.contains(it.key())) {
      c.Add(it.key(), "", "present", "missing");
      continue;
    }
    c.Field(it.key(), it.value(), f[it.key()]);
  }
  for (auto it = f.begin(); it != f.end(); ++it)
    if (!e.contains(it.key())) c.Add(it.key(), "", "missing", "present (a new field)");
  return out;
}

std::string Comparison::Report(const std::string& context, size_t max_shown) const {
  std::ostringstream os;
  std::set<std::string> fields;
  for (const Difference& d : differences) fields.insert(d.field);
  os << context << ": " << differences.size() << " difference(s) in " << fields.size()
     << " field(s), of " << values_compared << " values compared\n";
  for (size_t i = 0; i < differences.size() && i < max_shown; ++i) {
    const Difference& d = differences[i];
    os << "  " << d.field << (d.where.empty() ? "" : " [" + d.where + "]") << ": expected "
       << d.expected << ", found " << d.found;
    if (d.difference > 0) {
      os << ", difference " << Num(d.difference) << " > tolerance " << Num(d.tolerance.abs)
         << (d.tolerance.rel > 0 ? " + " + Num(d.tolerance.rel) + " x |value|" : "");
      if (!d.tolerance.why.empty()) os << " (" << d.tolerance.why << ")";
    }
    os << "\n";
  }
  if (differences.size() > max_shown) os << "  ... and " << differences.size() - max_shown << " more\n";
  return os.str();
}

std::string Summary(const Comparison& comparison) {
  struct Moved {
    size_t count = 0;
    double largest = 0;
    std::vector<std::string> where;  // the first few places
  };
  std::map<std::string, Moved> by_field;
  for (const Difference& d : comparison.differences) {
    Moved& m = by_field[d.field];
    ++m.count;
    m.largest = std::max(m.largest, d.difference);
    if (m.where.size() < 3 && !d.where.empty()) m.where.push_back(d.where);
  }
  std::ostringstream os;
  for (const auto& [field, m] : by_field) {
    os << "    " << field << ": " << m.count << " value(s)";
    if (m.largest > 0) os << ", largest difference " << Num(m.largest);
    if (!m.where.empty()) {
      os << " (";
      for (size_t i = 0; i < m.where.size(); ++i) os << (i ? "; " : "") << m.where[i];
      os << (m.count > m.where.size() ? "; ..." : "") << ")";
    }
    os << "\n";
  }
  return os.str();
}

}  // namespace jvl::golden
