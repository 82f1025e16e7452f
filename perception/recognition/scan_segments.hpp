#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/preprocessing/plane_removal.hpp"
#include "perception/recognition/object_recognizer.hpp"

namespace uwscan::perception {

// The segmentation stage of RecognizeObjects: the planes objects rest on, then the segments
// that may each be one object.

// A segment: its points (increasing indices) and the diameter of its own cluster (or clusters,
// when nearby segments joined), without the small fragments that joined it.
struct Segment {
  std::vector<std::size_t> indices;
  double core_diameter_m = 0.0;
};

// The planes objects rest on or stand beside: the dominant plane (the seabed), then others while
// they are wider than any object of the database both ways (a wall); the search stops at the
// first narrower one. A flat face of an object, or a slab cut through the tops of lying pipes,
// holds many points too, but removing it would cut the object in pieces. A plane no wider than an
// object that hides surface behind it (seen from the sensor at the origin) is an object's face
// seen broadside, a panel on the seabed or on a wall: it is kept, and the supports are sought
// among the other points. Uses options' plane_distance_m, plane_min_fraction
// (of `down`), min_segment_points, seed and threads.
PlaneRemovalResult RemoveSupportPlanes(const PointCloud& down, double largest_object_m,
                                       const RecognitionOptions& options);

// Euclidean clusters (cluster_tolerance_m) of at least min_segment_points, each with the smaller
// clusters within attach_distance_m of it (to the nearest segment): the parts of one object that
// occlusion separated, such as a valve's handle hiding its own stem from a sensor above it.
// Then segments within attach_distance_m of each other join, smallest first into its nearest,
// while together they are no wider than `largest_object_m`: a handwheel cut off from its valve
// by its own shadow is too big to attach as a fragment, yet alone it is no object of the
// database. (Two objects joined by mistake are split again by recognition.) Largest first
// (equal sizes in cluster order).
std::vector<Segment> Segments(const PointCloud& cloud, double largest_object_m,
                              const RecognitionOptions& options);

// The segment nearest to `part` (indices into `cloud`) other than segment `skip`: its index and
// the smallest point-to-point distance, or (0, infinity) when no other segment has a point.
std::pair<std::size_t, double> NearestSegment(const PointCloud& cloud,
                                              const std::vector<std::size_t>& part,
                                              const std::vector<Segment>& segments,
                                              std::size_t skip);

}  // namespace uwscan::perception
