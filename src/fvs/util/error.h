// Errors that reach the user as one line: "<file or subject>: <what is wrong>".
// Every stage throws fvs::Error on bad input; the commands catch it, print the line and
// exit non-zero. Nothing here aborts.
#pragma once

#include <stdexcept>
#include <string>

namespace fvs {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(OneLine(message)) {}
  Error(const std::string& subject, const std::string& what)
      : std::runtime_error(OneLine(subject.empty() ? what : subject + ": " + what)) {}

  // Library messages passed on (OpenImageIO's, LibTorch's) may span lines: joined with
  // "; " so that the user still gets one line.
  static std::string OneLine(const std::string& text) {
    std::string line;
    line.reserve(text.size());
    bool pending_break = false;
    for (const char c : text) {
      if (c == '\n' || c == '\r') {
        pending_break = !line.empty();
        continue;
      }
      if (pending_break) line += "; ";
      pending_break = false;
      line += c;
    }
    return line;
  }
};

// Throws Error(subject, what) when the condition does not hold.
inline void Require(bool condition, const std::string& subject, const std::string& what) {
  if (!condition) throw Error(subject, what);
}

}  // namespace fvs
