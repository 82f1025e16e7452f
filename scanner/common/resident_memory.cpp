#include "scanner/common/resident_memory.hpp"

#include <fstream>
#include <string>

namespace uwscan {

std::optional<std::int64_t> ResidentBytes(int pid) {
  std::ifstream status("/proc/" + (pid == 0 ? std::string("self") : std::to_string(pid)) +
                       "/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      std::int64_t kb = 0;
      if (!(status >> kb)) return std::nullopt;
      return kb * 1024;
    }
    status.ignore(1 << 12, '\n');
  }
  return std::nullopt;
}

}  // namespace uwscan
