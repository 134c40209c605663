#include "core/strings.h"

#include <charconv>
#include <cmath>

#include "core/check.h"

namespace jvl {

std::string_view Trim(std::string_view s) {
  const char* ws = " \t\r\n";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

std::vector<std::string_view> SplitWhitespace(std::string_view s, bool comma) {
  std::vector<std::string_view> out;
  size_t i = 0;
  auto is_sep = [comma](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || (comma && c == ',');
  };
  while (i < s.size()) {
    while (i < s.size() && is_sep(s[i])) ++i;
    size_t j = i;
    while (j < s.size() && !is_sep(s[j])) ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

std::optional<double> ParseDouble(std::string_view token) {
  if (token.empty()) return std::nullopt;
  if (token.front() == '+') token.remove_prefix(1);
  double value = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size()) return std::nullopt;
  return value;
}

std::optional<long long> ParseInt(std::string_view token) {
  if (token.empty()) return std::nullopt;
  if (token.front() == '+') token.remove_prefix(1);
  long long value = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size()) return std::nullopt;
  return value;
}

FrameRange ParseFrameRange(const std::string& text) {
  FrameRange range;
  if (text.empty()) return range;
  const auto colon = text.find(':');
  JVL_CHECK(colon != std::string::npos,
            "--frames: expected A:B (e.g. 0:100, :50, 10:), got '" << text << "'");
  const std::string_view a = Trim(std::string_view(text).substr(0, colon));
  const std::string_view b = Trim(std::string_view(text).substr(colon + 1));
  if (!a.empty()) {
    const auto v = ParseInt(a);
    JVL_CHECK(v && *v >= 0, "--frames: bad start '" << a << "' in '" << text << "'");
    range.first = *v;
  }
  if (!b.empty()) {
    const auto v = ParseInt(b);
    JVL_CHECK(v && *v > range.first,
              "--frames: end must be an integer > start in '" << text << "'");
    range.last_exclusive = *v;
  }
  return range;
}

std::string FormatDouble(double value) {
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), value);
  if (ec != std::errc()) return "nan";
  return std::string(buf, ptr);
}

}  // namespace jvl
