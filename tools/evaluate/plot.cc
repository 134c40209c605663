// Runs scripts/plot_eval.py; plotting is optional, so every failure is a warning.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/check.h"
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

std::string FindPlotPython(const std::string& requested) {
  if (!requested.empty()) {
    JVL_CHECK(HasMatplotlib(requested),
              "--python " << requested
                          << ": not a Python interpreter with matplotlib and numpy (it must run "
                             "'import matplotlib, numpy')");
    return requested;
  }
  for (const std::string p : {"python3", "/usr/bin/python3"})
    if (HasMatplotlib(p)) return p;
  return "";
}

bool MakePlots(const std::string& dir, const nlohmann::json& plot_data, std::string script,
               const std::string& python) {
  if (script.empty()) {
    const char* env = std::getenv("JVL_PLOT_SCRIPT");
    script = env ? env : JVL_PLOT_SCRIPT;
  }
  if (!io::FileExists(script)) {
    spdlog::warn("plots skipped: plotting script {} not found (set --plot-script)", script);
    return false;
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
  // The script's and matplotlib's own output (e.g. "building the font cache" on a new machine)
  // goes to the debug log, and to warnings only when the script fails.
  FILE* pipe = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!pipe) {
    spdlog::warn("plots skipped: cannot run '{}'", cmd);
    return false;
  }
  std::vector<std::string> lines;
  char buf[4096];
  while (std::fgets(buf, sizeof(buf), pipe)) {
    std::string line(buf);
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    spdlog::debug("plot_eval: {}", line);
    lines.push_back(std::move(line));
  }
  const int status = ::pclose(pipe);
  if (status != 0) {
    const size_t first = lines.size() > 5 ? lines.size() - 5 : 0;
    for (size_t i = first; i < lines.size(); ++i) spdlog::warn("plot_eval: {}", lines[i]);
    spdlog::warn("plots incomplete: '{}' failed", cmd);
    return false;
  }
  spdlog::info("plots written to {}", dir);
  return true;
}

}  // namespace jvl::tools
