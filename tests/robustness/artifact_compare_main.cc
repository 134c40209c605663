// artifact_compare: compares the outputs of two runs (see artifact_compare.h for what is ignored).
//
//   artifact_compare [--abs T] [--rel T] [--ignore-option NAME]... DIR_A DIR_B FILE...
//
// Prints one line per file (equal, or the number of differences, the largest absolute
// difference and the first differences) and exits with 1 when any file differs.
#include <cstdio>
#include <string>
#include <vector>

#include "artifact_compare.h"
#include "core/check.h"
#include "core/strings.h"

int main(int argc, char** argv) {
  using namespace jvl;
  testing::CompareOptions options;
  options.max_reported = 3;
  std::vector<std::string> positional;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        JVL_CHECK(i + 1 < argc, arg << ": missing value");
        return argv[++i];
      };
      auto number = [&]() {
        const std::string v = value();
        const auto d = ParseDouble(v);
        JVL_CHECK(d && *d >= 0, arg << ": expected a number >= 0, got '" << v << "'");
        return *d;
      };
      if (arg == "--abs") {
        options.abs_tolerance = number();
      } else if (arg == "--rel") {
        options.rel_tolerance = number();
      } else if (arg == "--ignore-option") {
        options.ignored_options.push_back(value());
      } else {
        positional.push_back(arg);
      }
    }
    JVL_CHECK(positional.size() >= 3,
              "usage: artifact_compare [--abs T] [--rel T] "
              "[--ignore-option NAME]... DIR_A DIR_B FILE...");
    bool all_equal = true;
    for (size_t k = 2; k < positional.size(); ++k) {
      const std::string& f = positional[k];
      const auto r =
          testing::CompareFiles(positional[0] + "/" + f, positional[1] + "/" + f, options);
      all_equal = all_equal && r.equal;
      if (r.equal) {
        std::printf("%-16s equal (max |diff| %.3g%s%s)\n", f.c_str(), r.max_abs_difference,
                    r.max_abs_where.empty() ? "" : " at ", r.max_abs_where.c_str());
        continue;
      }
      std::printf("%-16s %zu differences, max |diff| %.3g at %s\n", f.c_str(), r.difference_count,
                  r.max_abs_difference, r.max_abs_where.c_str());
      for (const std::string& d : r.differences) std::printf("    %s\n", d.c_str());
    }
    return all_equal ? 0 : 1;
  } catch (const Error& e) {
    std::fprintf(stderr, "artifact_compare: error: %s\n", e.message().c_str());
    return 2;
  }
}
