#include "app/tool.h"

#include <spdlog/spdlog.h>

#include <cstdio>

#include "core/check.h"
#include "core/logging.h"
#include "core/threads.h"
#include "io/version.h"

namespace jvl::app {

Tool::Tool(std::string name, std::string description)
    : name_(std::move(name)), cli_(std::move(description), name_) {
  cli_.set_version_flag("--version", std::string(name_) + " (jvldloc) " + JVL_VERSION + " " +
                                         JVL_GIT_REVISION);
  cli_.set_config("--config", "", "Read options from a TOML/INI file (same names as the flags)");
  cli_.add_option("--threads", threads_, "Worker threads (0 = all cores)")->capture_default_str();
  cli_.add_option("--log-level", log_level_, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  cli_.add_flag("--quiet", quiet_, "No progress output");
  cli_.get_formatter()->column_width(36);
}

int Tool::Run(int argc, const char* const* argv, const std::function<void()>& body) {
  try {
    cli_.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return cli_.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return cli_.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return cli_.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: error: %s (see --help)\n", name_.c_str(), e.what());
    return 2;
  }
  try {
    SetupLogging(log_level_);
    threads_ = ResolveThreadCount(threads_);
    timer_.Reset();
    body();
    return 0;
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: error: %s\n", name_.c_str(), e.message().c_str());
    spdlog::debug("raised at {}", e.what());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "%s: error: out of memory\n", name_.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name_.c_str(), e.what());
  }
  return 1;
}

void Tool::SetDatasetId(const std::string& id, const std::string& source) {
  JVL_CHECK(dataset_id_.empty() || id.empty() || id == dataset_id_,
            source << " is sequence '" << id << "' but " << dataset_source_ << " was made from '"
                   << dataset_id_ << "' (inputs of different sequences)");
  if (id.empty()) return;
  dataset_id_ = id;
  dataset_source_ = source;
}

void Tool::AddInput(const std::string& path, bool same_dataset) {
  inputs_.push_back(io::DescribeFile(path));
  if (!same_dataset) return;
  const std::string id = io::ReadArtifactDatasetId(path);
  JVL_CHECK(dataset_id_.empty() || id.empty() || id == dataset_id_,
            path << " was made from sequence '" << id << "' but " << dataset_source_ << " is '"
                 << dataset_id_ << "' (inputs of different sequences)");
  if (!id.empty() && dataset_id_.empty()) {
    dataset_id_ = id;
    dataset_source_ = path;
  }
}

nlohmann::json Tool::OptionsJson() const {
  nlohmann::json j = nlohmann::json::object();
  for (const CLI::Option* opt : cli_.get_options()) {
    const std::string name = opt->get_lnames().empty() ? opt->get_name() : opt->get_lnames()[0];
    if (name == "help" || name == "version" || name == "config") continue;
    std::vector<std::string> values = opt->results();
    if (values.empty()) {
      const std::string def = opt->get_default_str();
      if (!def.empty()) values.push_back(def);
    }
    if (opt->get_expected_max() > 1 || values.size() > 1) {
      j[name] = values;
    } else if (opt->get_type_size() == 0) {
      j[name] = opt->count() > 0;  // A flag.
    } else {
      j[name] = values.empty() ? std::string() : values[0];
    }
  }
  return j;
}

io::Provenance Tool::MakeProvenance() const {
  io::Provenance p;
  p.tool = name_;
  p.options = OptionsJson();
  p.inputs = inputs_;
  p.dataset_id = dataset_id_;
  p.wall_time_s = timer_.ElapsedSeconds();
  p.peak_memory_bytes = PeakMemoryBytes();
  return p;
}

}  // namespace jvl::app
