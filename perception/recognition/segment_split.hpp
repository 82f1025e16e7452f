#pragma once
// Internal to RecognizeObjects (object_recognizer.cpp), not the library's interface: a segment no
// single object explains (objects touching each other) searched for the part one object explains.

#include <cstddef>
#include <optional>
#include <vector>

#include "perception/recognition/segment_pose.hpp"

namespace uwscan::perception::recognition {

// A part of a segment that one object explains, with the object posed on the part alone.
struct ExplainedPart {
  PosedObject posed;
  std::vector<std::size_t> points;  // into the segment
  double share = 0.0;               // of the segment's points
};

// The object explaining the largest share of a segment that no single object explains (objects
// touching each other fall into one segment, whose outline resembles neither). The segment is
// cut in two halves (Halves), each recognised as a segment of its own for pose candidates (its
// split_candidates nearest by chi-square), and each candidate gives the part it explains
// (PartOnHalf). The part must hold min_part_share of
// the segment; parts are ranked by share x score, ties to the earlier half and candidate.
// Parallel over (half, candidate), each on one thread: the same answer for any thread count.
std::optional<ExplainedPart> ExplainPart(const DescribedSegment& s, const ScanContext& ctx);

}  // namespace uwscan::perception::recognition
