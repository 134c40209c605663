// Locale-independent parsing helpers for the text formats (KITTI, TUM, calibration).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace jvl {

std::string_view Trim(std::string_view s);
// Splits on runs of spaces/tabs (and commas when comma=true); empty tokens are dropped.
std::vector<std::string_view> SplitWhitespace(std::string_view s, bool comma = false);
// Strict: the whole token must be a finite or non-finite number ("nan", "inf" accepted).
std::optional<double> ParseDouble(std::string_view token);
std::optional<long long> ParseInt(std::string_view token);
// Parses "A:B" (inclusive A, exclusive B; either side may be empty) for --frames.
struct FrameRange {
  long long first = 0;
  long long last_exclusive = -1;  // -1 means "to the end"
  bool Contains(long long frame) const {
    return frame >= first && (last_exclusive < 0 || frame < last_exclusive);
  }
};
FrameRange ParseFrameRange(const std::string& text);
// Shortest round-trip text of a double ("%.17g" would also do; this is shorter and exact).
std::string FormatDouble(double value);

}  // namespace jvl
