#include "app/tool.h"

#include <spdlog/spdlog.h>

#include <glog/logging.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <thread>

#include "core/check.h"
#include "core/logging.h"
#include "core/threads.h"
#include "io/files.h"
#include "io/version.h"

namespace jvl::app {

Tool::Tool(std::string name, std::string description)
    : name_(std::move(name)), cli_(std::move(description), name_) {
  cli_.set_version_flag("--version", std::string(name_) + " (jvldloc) " + JVL_VERSION + " " +
                                         JVL_GIT_REVISION);
  cli_.set_config("--config", "", "Read options from a TOML/INI file (same names as the flags)");
  cli_.allow_config_extras(CLI::config_extras_mode::error);
  cli_.add_option("--threads", threads_, "Worker threads (0 = all cores)")->capture_default_str();
  cli_.add_option("--log-level", log_level_, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  cli_.add_flag("--quiet", quiet_, "No progress output");
  cli_.get_formatter()->column_width(36);
}

int Tool::Run(int argc, const char* const* argv, const std::function<void()>& body) {
  // Unsigned options (seeds, counts): CLI11 would read "-1" as 2^64 - 1.
  const CLI::Validator non_negative(
      [](std::string& value) {
        return !value.empty() && value.front() == '-'
                   ? "must be a non-negative integer, got " + value
                   : std::string();
      },
      "", "non-negative");
  for (CLI::Option* option : cli_.get_options()) {
    if (option->get_type_name() == "UINT") option->check(non_negative);
  }
  try {
    cli_.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return cli_.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return cli_.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return cli_.exit(e);
  } catch (const CLI::ConfigError& e) {
    // CLI11 names the key but not the file.
    const CLI::Option* config = cli_.get_config_ptr();
    const std::string file = config && !config->results().empty() ? config->results()[0] : "";
    std::fprintf(stderr, "%s: error: %s%s (see --help)\n", name_.c_str(),
                 file.empty() ? "" : (file + ": ").c_str(), e.what());
    return 2;
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: error: %s (see --help)\n", name_.c_str(), e.what());
    return 2;
  }
  try {
    SetupLogging(log_level_);
    io::InstallInterruptCleanup();
    // OpenCV picks SIMD code paths by the CPU it runs on (AVX2, AVX-512, ...), and they do not
    // round alike: on one machine without them the simulator's images differed by a grey level
    // in a few pixels and every later stage moved (local_map poses by 2 cm). Its baseline code
    // gives the same bytes on every x86-64 machine, at no measurable cost to vp_detect or
    // visual_assoc (docs/robustness.md, "Determinism").
    cv::setUseOptimized(false);
    // Ceres logs through glog: keep its lines (e.g. thread-count notices) off the terminal;
    // the tools report what matters through their own log.
    static bool glog_ready = false;
    if (!glog_ready) {
      FLAGS_minloglevel = 3;  // FATAL only
      FLAGS_logtostderr = true;
      google::InitGoogleLogging(name_.c_str());
      glog_ready = true;
    }
    const int requested = threads_;
    threads_ = ResolveThreadCount(threads_);
    const unsigned hw = std::thread::hardware_concurrency();
    if (hw > 0 && threads_ > static_cast<int>(hw)) {
      spdlog::warn("--threads {}: this machine has {} hardware threads; using {}", requested, hw,
                   hw);
      threads_ = static_cast<int>(hw);
    }
    CheckOutputs();
    timer_.Reset();
    body();
    return 0;
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: error: %s\n", name_.c_str(), WithFlags(e.message()).c_str());
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

void Tool::FieldFlag(const std::string& field, const std::string& flag) {
  field_flags_[field] = flag;
}

std::string Tool::WithFlags(const std::string& message) const {
  // Every snake_case word that names a field with a flag.
  std::string out;
  size_t i = 0;
  while (i < message.size()) {
    const auto word_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    if (!word_char(message[i]) || (i > 0 && (word_char(message[i - 1]) || message[i - 1] == '-'))) {
      out += message[i++];
      continue;
    }
    size_t end = i;
    while (end < message.size() && word_char(message[end])) ++end;
    const std::string word = message.substr(i, end - i);
    std::string flag;
    if (const auto it = field_flags_.find(word); it != field_flags_.end()) {
      flag = it->second;
    } else if (word.find('_') != std::string::npos) {
      std::string dashed = "--" + word;
      std::replace(dashed.begin(), dashed.end(), '_', '-');
      for (const CLI::Option* o : cli_.get_options())
        if (o->check_name(dashed)) flag = dashed;
    }
    out += flag.empty() ? word : flag;
    i = end;
  }
  return out;
}

CLI::Option* Tool::OutputFile(CLI::Option* option) {
  output_options_.push_back(option);
  return option;
}

CLI::Option* Tool::InputFile(CLI::Option* option) {
  input_options_.push_back(option);
  return option;
}

namespace {

std::string OptionName(const CLI::Option* option) {
  return option->get_lnames().empty() ? option->get_name() : "--" + option->get_lnames()[0];
}

}  // namespace

void Tool::CheckOutputs() const {
  for (size_t a = 0; a < output_options_.size(); ++a) {
    for (const std::string& pa : output_options_[a]->results()) {
      if (pa.empty()) continue;
      JVL_CHECK(!io::IsDirectory(pa), OptionName(output_options_[a])
                                          << " " << pa << ": is a folder (expected a file name)");
      for (size_t b = a + 1; b < output_options_.size(); ++b) {
        for (const std::string& pb : output_options_[b]->results()) {
          JVL_CHECK(pb.empty() || !io::SameFile(pa, pb),
                    OptionName(output_options_[a])
                        << " " << pa << " and " << OptionName(output_options_[b]) << " " << pb
                        << " are the same file (each output needs its own path)");
        }
      }
    }
  }
  for (const CLI::Option* in : input_options_)
    for (const std::string& path : in->results())
      if (!path.empty()) CheckNotAnOutput(path, OptionName(in));
}

void Tool::CheckNotAnOutput(const std::string& path, const std::string& what) const {
  for (const CLI::Option* out : output_options_) {
    for (const std::string& o : out->results()) {
      JVL_CHECK(o.empty() || !io::SameFile(o, path),
                "output " << OptionName(out) << " " << o << " is the same file as input " << what
                          << " " << path << " (refusing to overwrite an input)");
    }
  }
}

void Tool::AddDatasetOptions(io::DatasetOptions* options) {
  cli_.add_option("--format", options->format, io::kDatasetFormatHelp)->capture_default_str();
  cli_.add_option("--lidar", options->lidar, io::kDatasetLidarHelp)
      ->capture_default_str()
      ->check(CLI::IsMember({"default", "left", "right", "both"}));
  cli_.add_option("--gt-source", options->ground_truth, io::kDatasetGroundTruthHelp)
      ->capture_default_str()
      ->check(CLI::IsMember({"default", "ins", "radar"}));
  cli_.add_option("--calib", options->calibration, io::kDatasetCalibrationHelp);
}

void Tool::AddDataset(const io::Dataset& dataset, const std::string& source) {
  SetDatasetId(dataset.id(), source);
  for (const std::string& f : dataset.KeyFiles()) AddInput(f);
  if (!dataset.calibration_file().empty()) AddInput(dataset.calibration_file(), false);
  // Only outputs that already exist can be a dataset file; most runs skip the listing.
  bool any_exists = false;
  for (const CLI::Option* out : output_options_)
    for (const std::string& o : out->results()) any_exists |= !o.empty() && io::FileExists(o);
  if (!any_exists) return;
  for (const std::string& f : dataset.InputFiles()) CheckNotAnOutput(f, "dataset file");
}

void Tool::AddInput(const std::string& path, bool same_dataset) {
  CheckNotAnOutput(path, "file");
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

void Tool::Switch(const CLI::Option* option, const bool* value) { switches_[option] = value; }

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
    const auto sw = switches_.find(opt);
    if (sw != switches_.end()) {
      j[name] = *sw->second;
    } else if (opt->get_expected_max() == 0) {  // a flag without --no-: on if given
      j[name] = !opt->results().empty() && opt->results().back() == "true";
    } else if (opt->get_expected_max() > 1 || values.size() > 1) {
      j[name] = values;
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
