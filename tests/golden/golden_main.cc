// golden: digests and compares stage outputs against their golden files (tests/golden/README.md).
//
//   golden digest ARTIFACT NAME OUT.json        write the digest of ARTIFACT (a file or folder)
//   golden check GOLDEN.json ARTIFACT TOLERANCES [CONTEXT]
//                                               compare; exit 1 with a readable diff if it moved
//   golden diff OLD.json NEW.json TOLERANCES    what moved between two digests (exit 0)
#include <cstdio>
#include <exception>
#include <string>

#include "core/check.h"
#include "golden.h"
#include "io/files.h"

namespace {

nlohmann::json Load(const std::string& path) {
  try {
    return nlohmann::json::parse(jvl::io::ReadTextFile(path));
  } catch (const nlohmann::json::exception& e) {
    JVL_THROW(path << ": not valid JSON");
  }
}

int Usage() {
  std::fprintf(stderr,
               "usage: golden digest ARTIFACT NAME OUT.json\n"
               "       golden check GOLDEN.json ARTIFACT TOLERANCES [CONTEXT]\n"
               "       golden diff OLD.json NEW.json TOLERANCES\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace jvl::golden;
  try {
    const std::string command = argc > 1 ? argv[1] : "";
    if (command == "digest" && argc == 5) {
      jvl::io::WriteTextFileAtomic(argv[4], Digest(argv[2], argv[3]).dump(1) + "\n");
      return 0;
    }
    if (command == "check" && (argc == 5 || argc == 6)) {
      const nlohmann::json golden = Load(argv[2]);
      const Comparison c = Compare(golden, Digest(argv[3], golden.value("artifact", "?")),
                                   Tolerances::Load(argv[4]));
      if (c.ok()) {
        std::printf("%s: matches %s (%zu values)\n", argv[3], argv[2], c.values_compared);
        return 0;
      }
      std::fputs(c.Report(argc == 6 ? argv[5] : argv[3]).c_str(), stdout);
      return 1;
    }
    if (command == "diff" && argc == 5) {
      const Comparison c = Compare(Load(argv[2]), Load(argv[3]), Tolerances::Load(argv[4]));
      if (!c.ok()) std::fputs(Summary(c).c_str(), stdout);
      return 0;
    }
    return Usage();
  } catch (const jvl::Error& e) {
    std::fprintf(stderr, "golden: error: %s\n", e.message().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "golden: error: %s\n", e.what());
  }
  return 1;
}
