// error.h — the one exception type for setup errors (bad input, missing GL features, I/O).
// Thrown anywhere in app/, caught once in main, printed as a one-line message with a non-zero exit.
#pragma once
#include <stdexcept>
#include <string>

namespace caustica {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace caustica
