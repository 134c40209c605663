// Checks that throw jvl::Error with a message and the source location.
//
//   JVL_CHECK(n % 16 == 0, "file " << path << " has " << n << " bytes, not a multiple of 16");
//   JVL_THROW("unknown format '" << name << "'");
//
// Tools catch jvl::Error at the top level and print what() as one line.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace jvl {

class Error : public std::runtime_error {
 public:
  Error(const std::string& message, const char* file, int line);
  // The message without the source location, for tests and reports.
  const std::string& message() const { return message_; }

 private:
  std::string message_;
};

[[noreturn]] void ThrowError(const std::string& message, const char* file, int line);

}  // namespace jvl

#define JVL_THROW(msg_stream)                                   \
  do {                                                          \
    std::ostringstream jvl_check_os_;                           \
    jvl_check_os_ << msg_stream;                                \
    ::jvl::ThrowError(jvl_check_os_.str(), __FILE__, __LINE__); \
  } while (false)

#define JVL_CHECK(cond, msg_stream) \
  do {                              \
    if (!(cond)) {                  \
      JVL_THROW(msg_stream);        \
    }                               \
  } while (false)
