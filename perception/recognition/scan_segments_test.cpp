#include "perception/recognition/scan_segments.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace uwscan::perception {
namespace {

// A square patch of count x count points `spacing_m` apart in the plane z = `z_m`, its corner at
// (x_m, y_m).
void AddPatch(std::vector<Eigen::Vector3d>& points, double x_m, double y_m, double z_m, int count,
              double spacing_m) {
  for (int i = 0; i < count; ++i) {
    for (int j = 0; j < count; ++j)
      points.emplace_back(x_m + i * spacing_m, y_m + j * spacing_m, z_m);
  }
}

RecognitionOptions Options() {
  RecognitionOptions options;
  options.cluster_tolerance_m = 0.025;
  options.attach_distance_m = 0.075;
  options.min_segment_points = 150;
  return options;
}

// Two halves of one object that occlusion cut apart, each of 100 points (too few to count alone),
// 4 cm apart: farther than the clustering's reach, within the attach distance. With no segment
// near them to take them, they still make one segment together.
TEST(ScanSegments, FragmentsTooSmallAloneMakeASegmentTogether) {
  std::vector<Eigen::Vector3d> points;
  AddPatch(points, 0.0, 0.0, 1.0, 10, 0.004);
  AddPatch(points, 0.076, 0.0, 1.0, 10, 0.004);
  const PointCloud cloud = MakeCloud(points);
  const std::vector<Segment> segments = Segments(cloud, 0.3, Options());
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_EQ(segments[0].indices.size(), 200u);
  EXPECT_TRUE(std::is_sorted(segments[0].indices.begin(), segments[0].indices.end()));
  // Corner to corner: the two patches span 0.112 m by 0.036 m.
  EXPECT_NEAR(segments[0].core_diameter_m, std::hypot(0.112, 0.036), 1e-6);
}

// The same two fragments 10 cm apart (beyond the attach distance) are two pieces of nothing, and
// a group of fragments wider than any object of the database is no segment either.
TEST(ScanSegments, FragmentsTooFarApartOrTooWideStayLeftOut) {
  std::vector<Eigen::Vector3d> far;
  AddPatch(far, 0.0, 0.0, 1.0, 10, 0.004);
  AddPatch(far, 0.136, 0.0, 1.0, 10, 0.004);
  EXPECT_TRUE(Segments(MakeCloud(far), 0.3, Options()).empty());

  std::vector<Eigen::Vector3d> near;
  AddPatch(near, 0.0, 0.0, 1.0, 10, 0.004);
  AddPatch(near, 0.076, 0.0, 1.0, 10, 0.004);
  EXPECT_TRUE(Segments(MakeCloud(near), 0.1, Options()).empty()) << "wider than the largest object";
}

// A fragment near a segment joins it, as before: it is not made a segment of its own with
// another fragment.
TEST(ScanSegments, AFragmentNearASegmentJoinsIt) {
  std::vector<Eigen::Vector3d> points;
  AddPatch(points, 0.0, 0.0, 1.0, 20, 0.004);    // 400 points: a segment
  AddPatch(points, 0.126, 0.0, 1.0, 10, 0.004);  // 100 points 5 cm from it
  const std::vector<Segment> segments = Segments(MakeCloud(points), 0.3, Options());
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_EQ(segments[0].indices.size(), 500u);
}

}  // namespace
}  // namespace uwscan::perception
