// The frame every tool's main() uses:
//
//   int main(int argc, char** argv) {
//     jvl::app::Tool tool("vp_detect", "Detect up to 3 vanishing points per image.");
//     VpOptions options;
//     tool.cli().add_option("--min-length", options.min_length, "...")->capture_default_str();
//     return tool.Run(argc, argv, [&] { ...; tool.Commit(writer) ...; });
//   }
//
// Tool adds the common options (--version, --config, --threads, --log-level, --quiet), sets up
// logging, turns every exception into one line "<tool>: error: <message>" on stderr with exit
// code 1 (2 for bad command lines), and fills in the provenance of the artifacts it writes.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/timer.h"
#include "io/artifact.h"
#include "io/dataset.h"

namespace jvl::app {

class Tool {
 public:
  Tool(std::string name, std::string description);

  CLI::App& cli() { return cli_; }
  const std::string& name() const { return name_; }
  int threads() const { return threads_; }  // Resolved (>= 1) once Run() has parsed.
  bool quiet() const { return quiet_; }     // --quiet: no progress output.

  // Parses argv and runs body. Returns the process exit code.
  int Run(int argc, const char* const* argv, const std::function<void()>& body);

  // Marks an option as naming a file this tool writes. Before the body runs, Run() refuses two
  // outputs that are the same file, and an output that is the same file as an input option
  // (InputFile); AddInput and AddDataset refuse inputs that are outputs. "The same file" is
  // decided on resolved paths: symbolic links, "./" and hard links are seen through.
  CLI::Option* OutputFile(CLI::Option* option);
  // Marks an option as naming a file or folder this tool reads (checked against the outputs).
  CLI::Option* InputFile(CLI::Option* option);
  // Library checks name the option fields they reject ("samples_per_list must be >= 1"); in the
  // tool's error line a field is shown as its flag: the flag spelled like the field
  // (--samples-per-list) if the tool has one, else the flag given here.
  void FieldFlag(const std::string& field, const std::string& flag);
  // A switch whose variable the provenance records by value (the value it holds after parsing,
  // whether set by --x, --no-x or left at its default).
  void Switch(const CLI::Option* option, const bool* value);

  // Adds the options every tool that opens a dataset has: --format, --lidar, --gt-source and
  // --calib (io::DatasetOptions; the reader checks the values and the layout they apply to).
  void AddDatasetOptions(io::DatasetOptions* options);

  // Records a dataset as input: its sequence id (SetDatasetId), its key files and the --calib
  // file that replaced its calibration (AddInput), and refuses an output that is one of the
  // files the dataset's frames are read from.
  void AddDataset(const io::Dataset& dataset, const std::string& source);

  // Records an input file (path, size, content hash) for the provenance. The dataset id in an
  // artifact's provenance must match the run's (from SetDatasetId or an earlier input), so that
  // artifacts of different sequences are not mixed; the first one seen becomes the run's id.
  // Pass same_dataset = false for inputs that may come from other sequences (evaluate).
  void AddInput(const std::string& path, bool same_dataset = true);
  // The sequence this run works on (`source` names it in errors, e.g. the dataset folder).
  void SetDatasetId(const std::string& id, const std::string& source = "the dataset");
  // Provenance of this run so far: options, inputs, wall time and peak memory.
  io::Provenance MakeProvenance() const;
  // Options as JSON (name -> value as given or defaulted).
  nlohmann::json OptionsJson() const;

 private:
  // Throws if `path` (an input, named by `what`) is the same file as one of the outputs.
  void CheckNotAnOutput(const std::string& path, const std::string& what) const;
  void CheckOutputs() const;
  std::string WithFlags(const std::string& message) const;

  std::string name_;
  CLI::App cli_;
  std::vector<CLI::Option*> output_options_, input_options_;
  std::map<std::string, std::string> field_flags_;
  std::map<const CLI::Option*, const bool*> switches_;
  int threads_ = 0;
  std::string log_level_ = "info";
  bool quiet_ = false;
  std::vector<io::FileInfo> inputs_;
  std::string dataset_id_;
  std::string dataset_source_;  // What dataset_id_ came from, for error messages.
  Timer timer_;
};

}  // namespace jvl::app
