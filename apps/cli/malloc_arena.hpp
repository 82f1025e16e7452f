#pragma once

namespace uwscan::app {

// Serves every thread of the process from glibc's one main malloc arena. For commands whose
// mapper solves the whole graph on a thread of its own (MapperOptions::whole_solve_lag_s > 0):
// glibc gives such a thread an arena of its own, and the pages the solve's problem frees there
// stay with that arena, where the mapping thread never reuses them. On the 30-minute dive the
// resident set in its last tenth fell from 239 to 213 MB with one arena, at the same speed
// (bench/slam/RESULTS.md). Call before the command starts threads: a thread keeps the arena it
// was first given. Another allocator in glibc's place (a sanitizer's, a preloaded jemalloc) may
// ignore the setting: then its own policy stands, which costs memory, not correctness.
void UseOneMallocArena();

}  // namespace uwscan::app
