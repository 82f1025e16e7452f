#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace uwscan::bench {

// A fresh folder under the system's temporary directory, named after `purpose` and the process,
// removed on every way out (normal return or exception).
class ScratchFolder {
 public:
  explicit ScratchFolder(const std::string& purpose)
      : path_(std::filesystem::temp_directory_path() /
              ("uwscan-" + purpose + "-" + std::to_string(::getpid()))) {
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
  std::filesystem::path path_;
};

}  // namespace uwscan::bench
