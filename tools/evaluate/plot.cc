// Runs scripts/plot_eval.py; plotting is optional, so every failure is a warning.
#include <spdlog/spdlog.h>

#include <cstdlib>

#include "io/files.h"
#include "run.h"

namespace jvl::tools {

namespace {

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

bool HasMatplotlib(const std::string& python) {
  const std::string cmd = Quote(python) + " -c 'import matplotlib, numpy' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

}  // namespace

bool MakePlots(const std::string& dir, const nlohmann::json& plot_data, std::string script,
               std::string python) {
  if (script.empty()) {
    const char* env = std::getenv("JVL_PLOT_SCRIPT");
    script = env ? env : JVL_PLOT_SCRIPT;
  }
  if (!io::FileExists(script)) {
    spdlog::warn("plots skipped: plotting script {} not found (set --plot-script)", script);
    return false;
  }
  // The first interpreter that has matplotlib: --python, python3 on PATH, Debian's python3.
  std::vector<std::string> candidates;
  if (!python.empty()) candidates.push_back(python);
  candidates.push_back("python3");
  candidates.push_back("/usr/bin/python3");
  python.clear();
  for (const std::string& p : candidates) {
    if (HasMatplotlib(p)) {
      python = p;
      break;
    }
  }
  if (python.empty()) {
    spdlog::warn(
        "plots skipped: no python3 with matplotlib and numpy found (install "
        "python3-matplotlib, or pass --python)");
    return false;
  }
  io::CreateDirectories(dir);
  const std::string data = dir + "/plot_data.json";
  io::WriteTextFileAtomic(data, plot_data.dump() + "\n");
  const std::string cmd =
      Quote(python) + " " + Quote(script) + " " + Quote(data) + " " + Quote(dir);
  if (std::system(cmd.c_str()) != 0) {
    spdlog::warn("plots incomplete: '{}' failed (see its message above)", cmd);
    return false;
  }
  spdlog::info("plots written to {}", dir);
  return true;
}

}  // namespace jvl::tools
