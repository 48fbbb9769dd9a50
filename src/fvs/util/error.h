// Errors that reach the user as one line: "<file or subject>: <what is wrong>".
// Every stage throws fvs::Error on bad input; the commands catch it, print the line and
// exit non-zero. Nothing here aborts.
#pragma once

#include <stdexcept>
#include <string>

namespace fvs {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  Error(const std::string& subject, const std::string& what)
      : std::runtime_error(subject.empty() ? what : subject + ": " + what) {}
};

// Throws Error(subject, what) when the condition does not hold.
inline void Require(bool condition, const std::string& subject, const std::string& what) {
  if (!condition) throw Error(subject, what);
}

}  // namespace fvs
