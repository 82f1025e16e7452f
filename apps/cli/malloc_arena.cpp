#include "apps/cli/malloc_arena.hpp"

#include <malloc.h>

namespace uwscan::app {

void UseOneMallocArena() { mallopt(M_ARENA_MAX, 1); }

}  // namespace uwscan::app
