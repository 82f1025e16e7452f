#pragma once

// Procedurally generated objects of inspection, maintenance and repair (IMR) work: pipes,
// elbows, T-junctions, flanges, valves, intervention panels, gauge blocks, and the plain shapes
// scenes are built from. Every function returns a TriangleMesh in the object's own frame {O},
// metres.
//
// Closed shapes are watertight and oriented outward: every edge is shared by exactly two
// triangles, in opposite directions, and the signed volume is positive. Composite objects
// (tee, flange, valve) are unions of such closed parts that touch or overlap; each part is
// closed, so the mesh as a whole still pairs every edge, but its signed volume is the sum of
// the parts' volumes (overlaps counted twice), and surfaces of one part may run inside
// another. A ray caster sees exactly the outer surface of the union from outside, which is
// all a scanner ever looks at. The rectangle (a plane patch) is the one open shape.
//
// Curved surfaces are inscribed polygons: `chord_error_m` bounds how far a chord may stray
// from the true surface (the sagitta r (1 - cos(pi / n)) of n segments on radius r), so the
// default 0.1 mm gives 72 segments at 0.1 m radius.

#include <Eigen/Core>
#include <vector>

#include "scanner/common/triangle_mesh.hpp"

namespace uwscan::scanner::sim {

inline constexpr double kDefaultChordErrorM = 1e-4;

// Segments of a full circle of `radius_m` whose sagitta stays within chord_error_m: at least
// 8, rounded up to a multiple of 4 so that the four axis directions are vertices.
int CircleSegments(double radius_m, double chord_error_m = kDefaultChordErrorM);

// Rectangle size_x_m x size_y_m centred in the x-y plane of {O}, normal +z_O (2 triangles).
TriangleMesh MakeRectangle(double size_x_m, double size_y_m);

// Box of the given edge lengths centred on {O}, faces normal to the axes.
TriangleMesh MakeBox(const Eigen::Vector3d& size_m);

// Solid cylinder of radius_m, length_m along z_O, centred on {O}, with flat end caps.
TriangleMesh MakeCylinder(double radius_m, double length_m,
                          double chord_error_m = kDefaultChordErrorM);

// UV sphere centred on {O} (poles on z_O). Scenes ray cast spheres exactly; this mesh is for
// export and for recognition databases.
TriangleMesh MakeUvSphere(double radius_m, double chord_error_m = kDefaultChordErrorM);

// Straight pipe along z_O, centred on {O}: outer and inner cylinders and annular ends.
// Optionally a dent pressed into the outer wall (a change for `uwscan compare` to find): a smooth
// round hollow, dent_depth_m deep at its centre, falling to nothing at dent_radius_m from it
// along the surface (depth * (1 + cos(pi s / radius)) / 2 at distance s), centred at
// dent_angle_rad about z_O from x_O and dent_position_m along z_O. A dent radius with depth 0
// builds the same vertices undented, so that two epochs' meshes differ only in the dent.
struct PipeShape {
  double outer_radius_m = 0.05;
  double wall_m = 0.005;  // (0, outer_radius_m)
  double length_m = 0.5;
  double dent_radius_m = 0.0;    // 0: no dent; else in (0, pi * outer_radius_m), metres
  double dent_depth_m = 0.0;     // [0, wall_m), metres
  double dent_angle_rad = 0.0;   // finite
  double dent_position_m = 0.0;  // the dent within the length: |position| + radius < length / 2
  void Check() const;            // throws uwscan::Error naming the field
};
TriangleMesh MakePipe(const PipeShape& shape, double chord_error_m = kDefaultChordErrorM);

// Pipe elbow: a hollow torus section. Its centre line leaves {O} along +z_O and bends towards
// +x_O about the axis through (bend_radius_m, 0, 0) parallel to y_O, ending at
// (R (1 - cos a), 0, R sin a) heading (sin a, 0, cos a), R = bend radius, a = bend angle.
struct ElbowShape {
  double outer_radius_m = 0.05;
  double wall_m = 0.005;
  double bend_radius_m = 0.1;                  // of the centre line, > outer_radius_m
  double bend_angle_rad = 1.5707963267948966;  // (0, 2 pi)
  void Check() const;
};
TriangleMesh MakeElbow(const ElbowShape& shape, double chord_error_m = kDefaultChordErrorM);

// T-junction: a run pipe along z_O centred on {O}, and a branch pipe of the same section along
// +x_O from the run's axis to x = branch_length_m. A union of two closed pipes: the branch's
// first outer_radius_m lies inside the run (its inner end is hidden in the run's bore), so the
// outside is the tee's true outer surface, but the two bores are not joined.
struct TeeShape {
  double outer_radius_m = 0.05;
  double wall_m = 0.005;
  double run_length_m = 0.4;
  double branch_length_m = 0.2;  // from the run's axis, > outer_radius_m
  void Check() const;
};
TriangleMesh MakeTee(const TeeShape& shape, double chord_error_m = kDefaultChordErrorM);

// Pipe end with a welded-neck flange: a pipe along z_O, centred on {O}, whose last
// flange_thickness_m before +length_m / 2 widen to flange_radius_m (one closed surface of
// revolution), and `bolts` hexagonal bolt heads on the back face of the flange, evenly
// spaced on the circle half-way between the pipe and the flange rim (set 1 mm into the
// flange so that no faces coincide).
struct FlangeShape {
  double outer_radius_m = 0.05;
  double wall_m = 0.005;
  double length_m = 0.3;
  double flange_radius_m = 0.095;
  double flange_thickness_m = 0.02;
  int bolts = 8;                      // >= 0
  double bolt_head_radius_m = 0.009;  // across the corners of the hexagon
  double bolt_head_height_m = 0.008;
  // Bolt heads that are not there (a change for `uwscan compare` to find): indices in
  // [0, bolts), bolt k sitting at angle 2 pi (k + 1/2) / bolts about z_O from x_O.
  std::vector<int> missing_bolts;
  void Check() const;
};
TriangleMesh MakeFlange(const FlangeShape& shape, double chord_error_m = kDefaultChordErrorM);

// Valve on a pipe along z_O: a barrel-shaped body centred on {O}, a pipe stub on each side,
// a stem along +y_O and, on top of it, a hand wheel (rim, hub and two spokes, in a plane
// normal to y_O) or a lever (a bar along z_O).
enum class ValveHandle { kWheel, kLever };
struct ValveShape {
  double outer_radius_m = 0.05;  // of the pipe stubs
  double wall_m = 0.005;
  double body_radius_m = 0.075;  // > outer_radius_m
  double body_length_m = 0.14;
  double stub_length_m = 0.05;  // each stub beyond the body
  double stem_radius_m = 0.01;
  double stem_length_m = 0.13;  // from the pipe axis to the top of the stem, > body radius
  ValveHandle handle = ValveHandle::kWheel;
  double handle_radius_m = 0.06;  // wheel radius (to the rim's centre) or half the lever
  void Check() const;
};
TriangleMesh MakeValve(const ValveShape& shape, double chord_error_m = kDefaultChordErrorM);

// Intervention panel (as on subsea structures, ISO 13628-8): a plate in the x-y plane of {O},
// its front face at z = 0 facing +z_O, and two D-handles standing out of the front face, one
// each side of the centre along x_O, each two posts and a bar along y_O. Thin and flat: seen
// face-on it is mostly a plane, which recognition must not take for the seabed or a wall.
struct PanelShape {
  double width_m = 0.4;           // along x_O
  double height_m = 0.3;          // along y_O
  double thickness_m = 0.02;      // behind the front face, along -z_O
  double handle_offset_m = 0.12;  // each handle's bar at x = +-offset, < width / 2 - bar / 2
  double handle_span_m = 0.14;    // between the posts' centres, along y_O, < height_m
  double handle_depth_m = 0.06;   // the bar's top above the front face
  double bar_m = 0.02;            // the square section of the bars and posts
  void Check() const;
};
TriangleMesh MakePanel(const PanelShape& shape);

// Gauge block of the seed's experiment: length_m along y_O (20, 50 or 100 mm there), 35 mm
// along x_O, 9 mm along z_O, centred on {O}.
inline constexpr double kGaugeWidthM = 0.035;
inline constexpr double kGaugeThicknessM = 0.009;
TriangleMesh MakeGaugeBlock(double length_m);

}  // namespace uwscan::scanner::sim
