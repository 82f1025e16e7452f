#include "apps/cli/malloc_arena.hpp"

#include <malloc.h>

namespace uwscan::app {

void UseOneMallocArena() { mallopt(M_ARENA_MAX, 1); }

void MapLargeBlocksAlone() { mallopt(M_MMAP_THRESHOLD, kLargeBlockBytes); }

}  // namespace uwscan::app
