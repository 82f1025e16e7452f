#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

#include "scanner/common/temporary_folder.hpp"

namespace uwscan::bench {

// A fresh folder under the system's temporary directory, named after `purpose` and the process,
// removed on every way out (normal return or exception).
class ScratchFolder {
 public:
  // Throws uwscan::Error when there is no temporary folder ($TMPDIR not a folder).
  explicit ScratchFolder(const std::string& purpose) : path_(Under(purpose)) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  static std::filesystem::path Under(const std::string& purpose) {
    return TemporaryFolder() / ("uwscan-" + purpose + "-" + std::to_string(::getpid()));
  }
  std::filesystem::path path_;
};

}  // namespace uwscan::bench
