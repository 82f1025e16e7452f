#pragma once

namespace uwscan::perception {

// FLANN's squared Euclidean distance between two 3-D float points (its L2_Simple and L2_3D),
// term by term in the same order, so that searches written here pair exactly the points FLANN's
// kd-trees would.
inline float FlannSquaredDistance(float qx, float qy, float qz, float px, float py, float pz) {
  const float dx = qx - px;
  const float dy = qy - py;
  const float dz = qz - pz;
  float d = 0.0f;
  d += dx * dx;
  d += dy * dy;
  d += dz * dz;
  return d;
}

}  // namespace uwscan::perception
