#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/recognition/object_database.hpp"

namespace uwscan::perception {

// Starting poses that place a scan segment on an object model from a database view the
// segment resembles (by ESF). A view fixes the direction the object was seen from but not the
// roll about that line of sight (ESF does not change with it), so each start turns the view's
// line of sight onto the segment's, rolls about it, and puts the two centroids together. The
// first roll lines up the principal axes of the two point sets seen across the line of sight
// (an elongated pipe, tee or lever then starts aligned, up to a half turn); the others follow
// at equal steps of 2 pi / rolls, so round outlines, whose principal axes mean nothing, are
// covered too. An even `rolls` includes the first roll's half turn (the principal axis has no
// sign).
//
// segment_S: the segment in the sensor frame (sensor at the origin). Returns T_O_S per roll,
// the segment's frame in the object frame, first roll first. Throws uwscan::Error when rolls
// < 1 or either cloud is empty; a cloud whose centroid is at its sensor has no line of sight
// and gives no starts.
std::vector<Eigen::Isometry3d> ViewPoseHypotheses(const PointCloud& segment_S,
                                                  const ObjectView& view, int rolls);

}  // namespace uwscan::perception
