#include "scanner/lasers/scanner_yaml.hpp"

#include <cmath>

namespace uwscan::scanner::yaml {

PinholeCamera ReadCamera(const Context& where, const YAML::Node& node) {
  RequireKnownKeys(where, node,
                   {"width_px", "height_px", "fx_px", "fy_px", "cx_px", "cy_px", "distortion"});
  PinholeCamera c;
  c.width_px = Integer(where, node, "width_px");
  c.height_px = Integer(where, node, "height_px");
  c.fx_px = Number(where, node, "fx_px");
  c.fy_px = Number(where, node, "fy_px");
  c.cx_px = Number(where, node, "cx_px");
  c.cy_px = Number(where, node, "cy_px");
  const Eigen::VectorXd d = Vector(where, node, "distortion", 5);
  c.k1 = d[0], c.k2 = d[1], c.p1 = d[2], c.p2 = d[3], c.k3 = d[4];
  return c;
}

FlatViewport ReadViewport(const Context& where, const YAML::Node& node) {
  RequireKnownKeys(where, node,
                   {"normal", "distance_m", "thickness_m", "n_air", "n_glass", "n_water"});
  FlatViewport v;
  v.normal = Vector3(where, node, "normal");
  if (std::abs(v.normal.norm() - 1.0) > 1e-6) {
    Fail(Enter(where, "normal"), node["normal"], "expected a unit vector");
  }
  v.normal.normalize();
  v.distance_m = Number(where, node, "distance_m");
  v.thickness_m = Number(where, node, "thickness_m");
  v.n_air = NumberOr(where, node, "n_air", v.n_air);
  v.n_glass = NumberOr(where, node, "n_glass", v.n_glass);
  v.n_water = NumberOr(where, node, "n_water", v.n_water);
  return v;
}

}  // namespace uwscan::scanner::yaml
