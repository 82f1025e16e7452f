#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>

namespace uwscan {

// Vectors of independent draws, taken in a fixed order. Writing Vector3d(d(rng), d(rng),
// d(rng)) leaves the order of the three draws to the compiler (g++ evaluates constructor
// arguments right to left, clang left to right), so the same seed would give other data
// with another compiler. These helpers sequence the draws: x first, then y, then z (as a
// braced Vector3d{d(rng), d(rng), d(rng)} does too: a braced list is evaluated in order).

template <class Distribution, class Engine>
Eigen::Vector2d DrawVector2(Distribution& distribution, Engine& rng) {
  const double x = distribution(rng);
  const double y = distribution(rng);
  return {x, y};
}

template <class Distribution, class Engine>
Eigen::Vector3d DrawVector3(Distribution& distribution, Engine& rng) {
  const double x = distribution(rng);
  const double y = distribution(rng);
  const double z = distribution(rng);
  return {x, y, z};
}

// Draws in the order g++ gave the unsequenced Vector2d(d(rng), d(rng)) and Vector3d(d(rng),
// d(rng), d(rng)) (last component first), where data made before the draws were sequenced
// (benchmarks' published figures) must stay the same.
template <class Distribution, class Engine>
Eigen::Vector2d DrawVector2LastFirst(Distribution& distribution, Engine& rng) {
  const double y = distribution(rng);
  const double x = distribution(rng);
  return {x, y};
}

template <class Distribution, class Engine>
Eigen::Vector3d DrawVector3LastFirst(Distribution& distribution, Engine& rng) {
  const double z = distribution(rng);
  const double y = distribution(rng);
  const double x = distribution(rng);
  return {x, y, z};
}

// A uniformly distributed rotation: a normalised 4-vector of standard normal draws.
template <class Engine>
Eigen::Quaterniond DrawRotation(Engine& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const double w = normal(rng);
  const Eigen::Vector3d xyz = DrawVector3(normal, rng);
  return Eigen::Quaterniond(w, xyz.x(), xyz.y(), xyz.z()).normalized();
}

}  // namespace uwscan
