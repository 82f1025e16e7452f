#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench/progress.hpp"

// Recognition under the conditions users' data brings (issue 50), each its own figures: the
// catalogue's objects taught from their meshes (the reference) and from scans of them (clouds),
// scenes scanned by a depth camera instead of uwscan's scanner, and flat objects (intervention
// panels) lying on the seabed and mounted on a wall, which plane removal must not take for
// supports.
namespace uwscan::bench {

struct RecognitionConditionsOptions {
  int scans = 24;  // scenes per condition, >= 1
  int views = 16;  // database views per object, >= 1
  std::uint64_t seed = 1;
  int threads = 2;
  std::filesystem::path table_cache;  // cone table kept between runs
  std::filesystem::path data_cache;   // scripts/fetch_data.sh's folder: the CAD parts' meshes
  void Check() const;
};

// One recognised object: which scene, how far off, whether right, and its NEES.
struct ConditionPose {
  int scene = 0;
  std::string object;
  double rotation_rad = 0.0;       // modulo the truth's symmetries
  double translation_m = 0.0;      // the same
  bool right = false;              // counted in ConditionFigures::pose_success
  bool strict = false;             // counted in ConditionFigures::pose_strict
  bool right_or_reported = false;  // counted in ConditionFigures::pose_or_reported
  int equivalent_poses = 0;        // other poses the answer reported as fitting as well
  // Within 10 degrees and 5 cm, when the covariance pins a direction (below); none otherwise.
  std::optional<double> nees_per_dimension;
};

struct ConditionFigures {
  int objects = 0;       // objects scanned with enough points to count
  int recognised = 0;    // with the right id
  int pose_success = 0;  // of those, within 5 mm and 2 degrees modulo symmetry (PoseRight)
  // Of the recognised, within 5 mm and 2 degrees modulo only the symmetries the object truly has
  // (declared; none for the CAD parts, which pose_success judges by ADD-S instead)...
  int pose_strict = 0;
  // ...or off that but only by what the answer reports it cannot tell: a symmetry its model
  // carries (the database's, found for the CAD parts), an equivalent pose, a free slide or turn
  // (reported_ambiguity.hpp). recognised - pose_or_reported: poses wrong in what the answer
  // claims to know.
  int pose_or_reported = 0;
  double seconds = 0.0;  // recognition time, summed over the scans
  int scans = 0;
  // NEES per pinned direction of each posed object within 10 degrees and 5 cm (pose_nees.hpp)
  std::vector<double> nees_per_dimension;
  std::vector<ConditionPose> poses;  // every recognised object, one record each, in scene order
};

// "mesh_models", "cloud_models", "depth_camera", "catalogue_mm", "catalogue_mm_clouds",
// "flat_objects".
using RecognitionConditions = std::map<std::string, ConditionFigures>;

// Each condition's scenes: one object on a seabed (z = 0) at a random yaw, or for the flat objects
// a panel lying on the seabed or on a wall behind it, seen by the galvanometer scanner from
// 0.6-1.1 m at a random bearing, exact peaks with the simulator's peak noise. The cloud models
// are 50,000 points over each object's surface with 0.3 mm noise, written as PLY without faces
// and read back by build-db's reader (perception::CloudObject). The depth camera condition sees
// the mesh models' scenes from the same place with another sensor (sim::ScanWithDepthCamera's
// defaults: 320 x 240 pixels, depth noise 1.4 mm at 1 m growing with its square), the scan
// handed over as a PCD looking along -z with a VIEWPOINT and read back by the scan reader of
// `recognize`; the database is still the laser scanner's. The millimetre catalogue is six CGAL
// parts no other bench uses, each 0.3 m across, written as OBJ in millimetres and taught by
// build-db's reader given millimetres, in scenes of their own; the same parts are also taught from
// scans of them (clouds as above, written in millimetres and read given millimetres), on the same
// scenes and scored against the same truths. Throws uwscan::Error naming a
// missing mesh when the data cache lacks one. Deterministic for a seed.
RecognitionConditions RunRecognitionConditions(const RecognitionConditionsOptions& options,
                                               const Progress& progress = {});

}  // namespace uwscan::bench
