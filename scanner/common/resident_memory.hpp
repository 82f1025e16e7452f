#pragma once

#include <cstdint>
#include <optional>

namespace uwscan {

// The resident memory (VmRSS) of process `pid` (0: this one), bytes, from /proc; std::nullopt
// when it cannot be read (the process is gone, or no /proc).
std::optional<std::int64_t> ResidentBytes(int pid = 0);

}  // namespace uwscan
