// Method options of a tool, added in named groups with their defaults shown in --help: the one
// form every tool's cli_options.cc uses.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <utility>

#include "app/tool.h"

namespace jvl::app {

class OptionGroup {
 public:
  OptionGroup(Tool& tool, std::string name)
      : tool_(tool), cli_(tool.cli()), name_(std::move(name)) {}

  // `flags` as CLI11 spells them ("--samples-per-list", "-n,--name"); `value` is also the
  // default shown.
  template <typename T>
  CLI::Option* Add(const std::string& flags, T& value, const std::string& help) {
    return cli_.add_option(flags, value, help)->capture_default_str()->group(name_);
  }

  // A switch; "--name,!--no-name" gives both spellings, and then --help names the default
  // ("(default: on)"). The provenance records the value it leaves.
  CLI::Option* Flag(const std::string& flags, bool& value, const std::string& help) {
    const bool both = flags.find(',') != std::string::npos;
    const std::string text = both ? help + (value ? " (default: on)" : " (default: off)") : help;
    CLI::Option* option = cli_.add_flag(flags, value, text)->group(name_);
    tool_.Switch(option, &value);
    return option;
  }

  // An option whose flag is not spelled like its field: library messages that name the field
  // show the flag (Tool::FieldFlag).
  template <typename T>
  CLI::Option* Add(const std::string& flags, const std::string& field, T& value,
                   const std::string& help) {
    CLI::Option* option = Add(flags, value, help);
    tool_.FieldFlag(field, option->get_name());
    return option;
  }

 private:
  Tool& tool_;
  CLI::App& cli_;
  std::string name_;
};

}  // namespace jvl::app
