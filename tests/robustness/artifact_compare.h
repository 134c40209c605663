// Compares the outputs of two runs: HDF5 artifacts dataset by dataset and attribute by attribute,
// JSON artifacts value by value, text (poses, CSV, Markdown) number by number, anything else byte
// by byte. Ignored, because they legitimately change from run to run:
//   * the provenance time fields (io::ProvenanceTimeFields: created_utc, wall_time_s,
//     peak_memory_bytes) and the provenance options named in CompareOptions::ignored_options;
//   * measured run times inside statistics: JSON keys and dataset names ending in "_ms" or
//     "time_s" (e.g. diagnostics/time_ms, median_time_ms, total_time_s).
#pragma once

#include <string>
#include <vector>

namespace jvl::testing {

struct CompareOptions {
  // Numbers match when |a - b| <= abs_tolerance + rel_tolerance * max(|a|, |b|); with both 0
  // they must be bitwise equal (so NaN matches NaN of the same payload).
  double abs_tolerance = 0;
  double rel_tolerance = 0;
  // Options that differ between the runs compared (e.g. {"threads"}): ignored in the provenance
  // and as JSON keys anywhere (global_opt's stats record the solver's thread count).
  std::vector<std::string> ignored_options;
  size_t max_reported = 10;  // Differences listed in CompareResult::differences.
};

struct CompareResult {
  bool equal = true;
  std::vector<std::string> differences;  // The first max_reported, human-readable.
  size_t difference_count = 0;
  double max_abs_difference = 0;  // Over the numbers compared.
  std::string max_abs_where;      // Dataset / key / line of that difference.
};

CompareResult CompareFiles(const std::string& a, const std::string& b,
                           const CompareOptions& options);

// Whether `name` (a JSON key or dataset name) is a measured run time, ignored in comparisons.
bool IsRunTimeField(const std::string& name);

}  // namespace jvl::testing
