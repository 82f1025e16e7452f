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

// Serves every block of at least kLargeBlockBytes from pages of its own (glibc's
// M_MMAP_THRESHOLD, fixed), given back to the system when it is freed. For the ROS node, whose map
// publications late in a long dive allocate and free tens of megabytes each (the map's cloud, its
// message, the serialised copy): in the heap, their freed pages stayed resident between blocks
// that live on, and the node's memory grew with the map (bench/ros/RESULTS.md, "Large blocks on
// pages of their own": flat from minute 6 of the 30-minute soak, as with malloc_trim after each
// publication, without its walk of the heap under the arena's lock). A block made anew for every
// map is faulted in anew, page by page: the mapping thread keeps its map's cloud from one map to
// the next (MapPublisher::TakeSpare) for that reason. glibc's own threshold would rise to each such
// block's size when it is freed, up to 32 MB, and serve the next ones from the heap again. Call
// before the command starts threads.
constexpr int kLargeBlockBytes = 4 << 20;
void MapLargeBlocksAlone();

}  // namespace uwscan::app
