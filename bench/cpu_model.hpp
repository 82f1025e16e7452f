#pragma once

#include <string>

namespace uwscan::bench {

// The CPU the figures were measured on ("model name" of /proc/cpuinfo), so that an absolute
// rate in a report says where it was taken; "unknown" where the system does not say.
std::string CpuModel();

}  // namespace uwscan::bench
