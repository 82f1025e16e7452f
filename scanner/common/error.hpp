#pragma once

#include <stdexcept>
#include <string>

// The one error hierarchy of uwscan. It lives in the lowest module so that every module can
// throw it; it is the only name uwscan puts directly in namespace uwscan.
namespace uwscan {

// Bad input, configuration or I/O. The message names the file, line or field and what was
// expected. Expected numerical outcomes (a ray missing a surface) are values, never this.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace uwscan
