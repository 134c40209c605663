#include "artifact_compare.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/check.h"
#include "core/strings.h"
#include "io/artifact.h"
#include "io/files.h"

namespace jvl::testing {

bool IsRunTimeField(const std::string& name) {
  const std::string leaf = name.substr(name.find_last_of('/') + 1);
  auto ends_with = [&](const std::string& suffix) {
    return leaf.size() >= suffix.size() &&
           leaf.compare(leaf.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends_with("_ms") || ends_with("time_s");
}

namespace {

using nlohmann::json;

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

class Comparer {
 public:
  Comparer(const CompareOptions& options, CompareResult* result)
      : options_(options), result_(result) {}

  void Differ(const std::string& what) {
    result_->equal = false;
    ++result_->difference_count;
    if (result_->differences.size() < options_.max_reported) result_->differences.push_back(what);
  }

  void Numbers(double a, double b, const std::string& where) {
    const bool exact = options_.abs_tolerance == 0 && options_.rel_tolerance == 0;
    const double diff = std::abs(a - b);
    if (std::isfinite(diff) && diff > result_->max_abs_difference) {
      result_->max_abs_difference = diff;
      result_->max_abs_where = where;
    }
    bool same;
    if (exact) {
      same = std::memcmp(&a, &b, sizeof(double)) == 0;
    } else {
      same = (std::isnan(a) && std::isnan(b)) || a == b ||
             diff <= options_.abs_tolerance +
                         options_.rel_tolerance * std::max(std::abs(a), std::abs(b));
    }
    if (!same) {
      std::ostringstream s;
      s.precision(17);
      s << where << ": " << a << " vs " << b;
      Differ(s.str());
    }
  }

  void Json(const json& a, const json& b, const std::string& where) {
    if (a.is_number() && b.is_number()) {
      if (a.is_number_float() || b.is_number_float()) {
        Numbers(a.get<double>(), b.get<double>(), where);
      } else if (a != b) {
        Differ(where + ": " + a.dump() + " vs " + b.dump());
      }
      return;
    }
    if (a.type() != b.type()) return Differ(where + ": " + a.dump() + " vs " + b.dump());
    if (a.is_object()) {
      for (auto it = a.begin(); it != a.end(); ++it) {
        if (Ignored(it.key())) continue;
        if (!b.contains(it.key())) {
          Differ(where + "/" + it.key() + ": only in the first");
        } else {
          Json(it.value(), b[it.key()], where + "/" + it.key());
        }
      }
      for (auto it = b.begin(); it != b.end(); ++it)
        if (!Ignored(it.key()) && !a.contains(it.key()))
          Differ(where + "/" + it.key() + ": only in the second");
    } else if (a.is_array()) {
      if (a.size() != b.size()) {
        return Differ(where + ": " + std::to_string(a.size()) + " vs " + std::to_string(b.size()) +
                      " elements");
      }
      for (size_t i = 0; i < a.size(); ++i) Json(a[i], b[i], where + "[" + std::to_string(i) + "]");
    } else if (a != b) {
      Differ(where + ": " + a.dump() + " vs " + b.dump());
    }
  }

  bool Ignored(const std::string& key) const {
    return IsRunTimeField(key) ||
           std::find(options_.ignored_options.begin(), options_.ignored_options.end(), key) !=
               options_.ignored_options.end();
  }

  // Provenance without what changes from run to run: time fields, ignored options, and the
  // content hash and size of artifact inputs (they embed their own run times).
  json Stable(json provenance) const {
    if (!provenance.is_object()) return provenance;
    for (const std::string& f : io::ProvenanceTimeFields()) provenance.erase(f);
    if (provenance.contains("options") && provenance["options"].is_object())
      for (const std::string& o : options_.ignored_options) provenance["options"].erase(o);
    if (provenance.contains("inputs") && provenance["inputs"].is_array()) {
      for (json& in : provenance["inputs"]) {
        const std::string path = in.value("path", "");
        if (EndsWith(path, ".h5") || EndsWith(path, ".json")) {
          in.erase("hash");
          in.erase("size");
        }
      }
    }
    return provenance;
  }

  void JsonArtifacts(const std::string& a, const std::string& b) {
    json ja, jb;
    try {
      ja = json::parse(io::ReadTextFile(a));
      jb = json::parse(io::ReadTextFile(b));
    } catch (const json::exception& e) {
      return Differ(std::string("not valid JSON: ") + e.what());
    }
    if (ja.is_object() && ja.contains("provenance")) ja["provenance"] = Stable(ja["provenance"]);
    if (jb.is_object() && jb.contains("provenance")) jb["provenance"] = Stable(jb["provenance"]);
    Json(ja, jb, "");
  }

  void Text(const std::string& a, const std::string& b) {
    std::istringstream sa(io::ReadTextFile(a)), sb(io::ReadTextFile(b));
    std::string la, lb;
    int line = 0;
    while (true) {
      const bool more_a = static_cast<bool>(std::getline(sa, la));
      const bool more_b = static_cast<bool>(std::getline(sb, lb));
      ++line;
      if (!more_a || !more_b) {
        if (more_a != more_b) Differ("line " + std::to_string(line) + ": one file ends here");
        return;
      }
      const auto ta = SplitWhitespace(la, /*comma=*/true), tb = SplitWhitespace(lb, true);
      const std::string where = "line " + std::to_string(line);
      if (ta.size() != tb.size()) {
        Differ(where + ": '" + la + "' vs '" + lb + "'");
        continue;
      }
      for (size_t i = 0; i < ta.size(); ++i) {
        const auto da = ParseDouble(ta[i]), db = ParseDouble(tb[i]);
        if (da && db) {
          Numbers(*da, *db, where + " column " + std::to_string(i + 1));
        } else if (ta[i] != tb[i]) {
          Differ(where + ": '" + std::string(ta[i]) + "' vs '" + std::string(tb[i]) + "'");
        }
      }
    }
  }

  void Bytes(const std::string& a, const std::string& b) {
    const std::string ba = io::ReadTextFile(a), bb = io::ReadTextFile(b);
    if (ba.size() != bb.size()) {
      return Differ("sizes differ: " + std::to_string(ba.size()) + " vs " +
                    std::to_string(bb.size()) + " bytes");
    }
    const auto mismatch = std::mismatch(ba.begin(), ba.end(), bb.begin());
    if (mismatch.first != ba.end())
      Differ("first differing byte at offset " + std::to_string(mismatch.first - ba.begin()));
  }

  void H5(const std::string& a, const std::string& b) {
    const io::H5Reader ra(a, "", 0), rb(b, "", 0);
    if (ra.schema() != rb.schema() || ra.schema_version() != rb.schema_version()) {
      return Differ("schema " + ra.schema() + " v" + std::to_string(ra.schema_version()) + " vs " +
                    rb.schema() + " v" + std::to_string(rb.schema_version()));
    }
    const auto da = ra.ListDatasets(), db = rb.ListDatasets();
    if (da != db) return Differ("the files hold different datasets");
    for (const std::string& name : da) {
      if (IsRunTimeField(name)) continue;
      if (ra.Dims(name) != rb.Dims(name) || ra.DatasetType(name) != rb.DatasetType(name)) {
        Differ(name + ": shape or type differs");
        continue;
      }
      if (ra.DatasetType(name).rfind("float", 0) == 0) {
        const auto va = ra.ReadArray<double>(name), vb = rb.ReadArray<double>(name);
        for (size_t i = 0; i < va.size(); ++i)
          Numbers(va[i], vb[i], name + "[" + std::to_string(i) + "]");
      } else {
        const auto va = ra.ReadArray<int64_t>(name), vb = rb.ReadArray<int64_t>(name);
        for (size_t i = 0; i < va.size(); ++i) {
          if (va[i] != vb[i]) {
            Differ(name + "[" + std::to_string(i) + "]: " + std::to_string(va[i]) + " vs " +
                   std::to_string(vb[i]));
          }
        }
      }
    }
    const auto aa = ra.ListAttributes(), ab = rb.ListAttributes();
    if (aa != ab) return Differ("the files hold different attributes");
    for (const std::string& name : aa) {
      if (name == "schema_version") continue;  // Compared above (not a string).
      const std::string sa = ra.ReadString(name), sb = rb.ReadString(name);
      const json ja = json::parse(sa, nullptr, /*allow_exceptions=*/false);
      const json jb = json::parse(sb, nullptr, false);
      if (ja.is_discarded() || jb.is_discarded() || !ja.is_structured()) {
        if (sa != sb) Differ("attribute " + name + ": '" + sa + "' vs '" + sb + "'");
      } else if (name == "provenance") {
        Json(Stable(ja), Stable(jb), "provenance");
      } else {
        Json(ja, jb, "attribute " + name);
      }
    }
  }

 private:
  const CompareOptions& options_;
  CompareResult* result_;
};

}  // namespace

CompareResult CompareFiles(const std::string& a, const std::string& b,
                           const CompareOptions& options) {
  CompareResult result;
  Comparer c(options, &result);
  for (const std::string& p : {a, b}) {
    if (!io::FileExists(p)) {
      c.Differ(p + ": file not found");
      return result;
    }
  }
  if (EndsWith(a, ".h5")) {
    c.H5(a, b);
  } else if (EndsWith(a, ".json")) {
    c.JsonArtifacts(a, b);
  } else if (EndsWith(a, ".txt") || EndsWith(a, ".csv") || EndsWith(a, ".md")) {
    c.Text(a, b);
  } else {
    c.Bytes(a, b);
  }
  return result;
}

}  // namespace jvl::testing
