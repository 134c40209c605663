// Golden files: a compact, committed digest of what a stage wrote, and a field-aware comparison
// of a new run against it (tests/golden/README.md).
//
// A digest is JSON. Every field of the artifact becomes an entry of "fields":
//   * an HDF5 dataset, a numeric text file (KITTI poses, times.txt, CSV) or a scan: its shape,
//     a deterministic sample of rows (at most kSampleRows, evenly spread, first and last always),
//     labelled with the frame or keyframe id where the artifact has one, the column sums over
//     all rows, and for integer data a hash of all values;
//   * a JSON attribute or JSON artifact body: the value itself;
//   * an image: its size, mean and standard deviation, and a hash of its pixels.
// Excluded by rule, not per test: the provenance (times, paths, hosts, revisions, options),
// measured run times (names ending in "_ms" or "time_s") and the thread count anywhere, and the
// text of strings that name files (only their presence is compared).
//
// The comparison is exact for integers, strings and hashes; floats match within the tolerance
// of the first rule in tests/golden/tolerances.json whose pattern matches "<artifact>:<field>".
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace jvl::golden {

inline constexpr int kSampleRows = 24;

// Digest of an artifact file (.h5, .json, .txt, .csv, .bin, .png) or of a folder (every such
// file under it, e.g. a sim_sequence output). `name` is how the artifact is called in reports.
nlohmann::json Digest(const std::string& path, const std::string& name);

struct Tolerance {
  double abs = 0, rel = 0;
  std::string why;
};

// Tolerance rules: JSON array of {"match": glob, "abs": a, "rel": r, "why": text}.
class Tolerances {
 public:
  static Tolerances Load(const std::string& path);
  // The first rule matching "<artifact>:<field>"; exact (0, 0) if none does.
  Tolerance For(const std::string& artifact, const std::string& field) const;

 private:
  struct Rule {
    std::string match;
    Tolerance tolerance;
  };
  std::vector<Rule> rules_;
};

struct Difference {
  std::string field;     // "trajectory/poses"
  std::string where;     // "frame 17, tx" / "row 3" / "sum of column 2" / "/kitti/segments"
  std::string expected, found;
  double difference = 0;  // |found - expected| for numbers, else 0
  Tolerance tolerance;
};

struct Comparison {
  std::vector<Difference> differences;  // all of them
  size_t values_compared = 0;
  bool ok() const { return differences.empty(); }
  // The first `max_shown` differences, one line each, and the count of the others.
  std::string Report(const std::string& context, size_t max_shown = 8) const;
};

Comparison Compare(const nlohmann::json& expected, const nlohmann::json& found,
                   const Tolerances& tolerances);

// Largest |difference| per field, for the regenerate command's summary ("what moved").
std::string Summary(const Comparison& comparison);

}  // namespace jvl::golden
