#pragma once

#include <cstdint>
#include <optional>

namespace uwscan {

// The resident memory (VmRSS) of process `pid` (0: this one), bytes, from /proc; std::nullopt
// when it cannot be read (the process is gone, or no /proc).
std::optional<std::int64_t> ResidentBytes(int pid = 0);

// This process's heap as glibc's allocator sees it, over all its arenas (mallinfo2): what the
// program holds, and what the allocator holds from the system for it (held - in use is freed
// memory it keeps: fragmentation, when it grows). Resident memory that grows with `in_use` is
// the program's; with `held` alone, the allocator's.
struct HeapBytes {
  std::int64_t in_use = 0;
  std::int64_t held = 0;
};
HeapBytes CurrentHeapBytes();

// Gives the pages the allocator holds free back to the system (glibc's malloc_trim, which also
// releases free pages between blocks in use). After a large short-lived allocation, such as the
// problem of a whole pose graph's solve, they would otherwise stay resident: the blocks allocated
// after it keep the heap from shrinking.
void ReturnFreePages();

}  // namespace uwscan
