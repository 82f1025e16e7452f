#pragma once

// Point-cloud preprocessing, one concept per header: voxel downsampling, statistical outlier
// removal, normals and surface variation, RANSAC plane removal, Euclidean clustering and
// curvature keypoints. The seed's keypoint extraction is RemovePlanes, then EstimateNormals,
// then CurvatureKeypoints.

#include "perception/clustering.hpp"
#include "perception/keypoints.hpp"
#include "perception/normals.hpp"
#include "perception/outlier_filter.hpp"
#include "perception/plane_removal.hpp"
#include "perception/voxel_filter.hpp"
