#include "scanner/common/resident_memory.hpp"

#include <malloc.h>

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

HeapBytes CurrentHeapBytes() {
  const struct mallinfo2 info = mallinfo2();
  // Blocks too large for an arena are mapped on their own (hblkhd): held and in use both.
  return {static_cast<std::int64_t>(info.uordblks + info.hblkhd),
          static_cast<std::int64_t>(info.arena + info.hblkhd)};
}

void ReturnFreePages() { malloc_trim(0); }

}  // namespace uwscan
