#include "apps/cli/malloc_arena.hpp"

#include <malloc.h>

#include "scanner/common/error.hpp"

namespace uwscan::app {

void UseOneMallocArena() {
  if (mallopt(M_ARENA_MAX, 1) != 1) throw Error("malloc: glibc refused M_ARENA_MAX = 1");
}

}  // namespace uwscan::app
