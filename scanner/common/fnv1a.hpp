#pragma once

#include <cstddef>
#include <cstdint>

namespace uwscan {

// 64-bit FNV-1a hash of a byte range: the checksum of uwscan's own binary files (object
// databases, cached tables). Catches damage, not tampering.
inline std::uint64_t Fnv1a64(const char* data, std::size_t size) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace uwscan
