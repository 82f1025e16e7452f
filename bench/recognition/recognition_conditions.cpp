#include "bench/recognition/recognition_conditions.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>

#include "bench/recognition/pose_nees.hpp"
#include "bench/recognition/reported_ambiguity.hpp"
#include "bench/registration/registration_pairs.hpp"
#include "bench/scratch_folder.hpp"
#include "mapping/reconstruction/scan_file.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/recognition/object_catalogue.hpp"
#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_pose_search.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "perception/recognition/object_symmetry.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/depth_camera.hpp"
#include "scanner/sim/imr_objects.hpp"
#include "scanner/sim/virtual_scanner.hpp"

namespace uwscan::bench {
namespace {

namespace sim = scanner::sim;
using perception::ObjectDatabase;
using perception::ObjectSource;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr const char* kObjects[] = {"elbow", "flange", "pipe", "tee", "valve_lever", "valve_wheel"};
// CAD and scanned parts from CGAL's data no other bench or test uses (scripts/fetch_data.sh).
constexpr const char* kCadMeshes[] = {"dragknob",         "part",         "handle",
                                      "mech-holes-shark", "ALSTOM_TEST4", "itemb"};
constexpr double kCadSize_m = 0.3;      // each part's bounding-box diagonal, as built
constexpr int kMinVisiblePoints = 300;  // an object with fewer scan points is not scored
constexpr int kCloudPoints = 50000;     // a scan of all of an object's sides
constexpr double kCloudNoise_m = 0.0003;

// One scene: the objects (the scanned object is [1]), the true pose of [1] and the camera.
struct Scene {
  std::vector<sim::SceneObject> objects;
  std::string id;  // the true object's id
  Eigen::Isometry3d T_W_O = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
};

sim::SceneObject Placed(const std::string& name, const scanner::TriangleMesh& mesh,
                        const Eigen::Isometry3d& T_W_O) {
  sim::SceneObject o;
  o.name = name;
  o.shape = sim::ObjectShape::kMesh;
  o.mesh = mesh;
  o.T_W_O = T_W_O;
  return o;
}

sim::SceneObject Seabed() {
  sim::SceneObject seabed =
      Placed("seabed", sim::MakeRectangle(4.0, 4.0), Eigen::Isometry3d::Identity());
  seabed.shape = sim::ObjectShape::kPlane;
  return seabed;
}

// The camera at `range_m` from `target_W`, seen at `bearing_rad` about z and `elevation_rad`
// above the horizontal.
Eigen::Isometry3d CameraAt(const Eigen::Vector3d& target_W, double bearing_rad,
                           double elevation_rad, double range_m) {
  const Eigen::Vector3d from(std::cos(elevation_rad) * std::cos(bearing_rad),
                             std::cos(elevation_rad) * std::sin(bearing_rad),
                             std::sin(elevation_rad));
  return sim::LookAt(target_W + range_m * from, target_W, Eigen::Vector3d::UnitZ());
}

// A catalogue object resting on the seabed, y_O up, at a random yaw, seen from above and aside.
Scene ObjectScene(const ObjectSource& object, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::Matrix3d lay;
  lay << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // x_O -> x, y_O -> z, z_O -> -y
  Scene scene;
  scene.id = object.id;
  scene.T_W_O.linear() =
      Eigen::AngleAxisd(2.0 * std::numbers::pi * unit(rng), Eigen::Vector3d::UnitZ()) * lay;
  double lowest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& v : object.mesh.vertices)
    lowest = std::min(lowest, (scene.T_W_O.linear() * v).z());
  scene.T_W_O.translation() = Eigen::Vector3d(0.0, 0.0, -lowest);
  scene.objects = {Seabed(), Placed(object.id, object.mesh, scene.T_W_O)};
  const double bearing = 2.0 * std::numbers::pi * unit(rng);
  const double elevation = (35.0 + 30.0 * unit(rng)) * kDeg;
  const double range = 0.6 + 0.5 * unit(rng);
  scene.T_W_C = CameraAt(scene.T_W_O.translation(), bearing, elevation, range);
  return scene;
}

// An intervention panel lying on the seabed, handles up, or (every other scene) mounted on a
// wall (the plane y = 0.3, facing -y) above the seabed, seen from in front.
Scene PanelScene(const ObjectSource& panel, int index, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const sim::PanelShape shape;
  Scene scene;
  scene.id = panel.id;
  if (index % 2 == 0) {
    scene.T_W_O.linear() =
        Eigen::AngleAxisd(2.0 * std::numbers::pi * unit(rng), Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    scene.T_W_O.translation() = Eigen::Vector3d(0.0, 0.0, shape.thickness_m);
    scene.objects = {Seabed(), Placed(panel.id, panel.mesh, scene.T_W_O)};
    scene.T_W_C = CameraAt(scene.T_W_O.translation(), 2.0 * std::numbers::pi * unit(rng),
                           (40.0 + 25.0 * unit(rng)) * kDeg, 0.6 + 0.5 * unit(rng));
    return scene;
  }
  sim::SceneObject wall = Seabed();
  wall.name = "wall";
  wall.T_W_O.linear() << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // normal -y
  wall.T_W_O.translation() = Eigen::Vector3d(0.0, 0.3, 1.0);
  scene.T_W_O.linear() = wall.T_W_O.linear() * Eigen::AngleAxisd(2.0 * std::numbers::pi * unit(rng),
                                                                 Eigen::Vector3d::UnitZ());
  scene.T_W_O.translation() = Eigen::Vector3d(0.0, 0.3 - shape.thickness_m, 0.3 + 0.3 * unit(rng));
  scene.objects = {Seabed(), Placed(panel.id, panel.mesh, scene.T_W_O), wall};
  scene.T_W_C = CameraAt(scene.T_W_O.translation(), -0.5 * std::numbers::pi + (unit(rng) - 0.5),
                         (5.0 + 30.0 * unit(rng)) * kDeg, 0.6 + 0.5 * unit(rng));
  return scene;
}

// A CGAL part as a CAD export brings it: scaled to kCadSize_m across about its box's centre,
// written in millimetres as OBJ, and read back by build-db's reader given millimetres.
ObjectSource CadObject(const std::filesystem::path& data_cache, const std::string& name,
                       const std::filesystem::path& folder) {
  const scanner::TriangleMesh mesh = scanner::LoadMesh(data_cache / "meshes" / (name + ".off"));
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices) box.extend(v);
  const double to_mm = 1000.0 * kCadSize_m / box.diagonal().norm();
  const std::filesystem::path path = folder / (name + ".obj");
  {
    std::ofstream obj(path);
    obj.precision(9);
    for (const Eigen::Vector3d& v : mesh.vertices) {
      const Eigen::Vector3d mm = to_mm * (v - box.center());
      obj << "v " << mm.x() << ' ' << mm.y() << ' ' << mm.z() << '\n';
    }
    for (const Eigen::Vector3i& t : mesh.triangles)
      obj << "f " << t.x() + 1 << ' ' << t.y() + 1 << ' ' << t.z() + 1 << '\n';
    if (!obj.flush()) throw Error("recognition conditions: cannot write " + path.string());
  }
  return perception::MeshObject(path, 0.001);
}

// A scan of all of `mesh`'s sides (in metres) as a user would bring it: a PLY without faces in
// units of units_to_m metres, read back as build-db reads it given those units.
ObjectSource ScannedObject(const std::string& id, const scanner::TriangleMesh& mesh,
                           const std::filesystem::path& folder, std::uint64_t seed,
                           double units_to_m = 1.0) {
  const std::filesystem::path path = folder / (id + ".ply");
  std::vector<Eigen::Vector3d> points =
      scanner::ScannedSurface(mesh, kCloudPoints, kCloudNoise_m, seed);
  for (Eigen::Vector3d& p : points) p /= units_to_m;
  perception::WriteCloud(path, perception::MakeCloud(points));
  return perception::CloudObject(path, units_to_m);
}

// The scene seen by a depth camera where the laser scanner stood, brought as a user of such a
// camera would bring it: a PCD in a frame looking along -z with x right and y up (the graphics
// convention), its VIEWPOINT giving the camera's pose in that frame, read back by the reader
// `recognize` uses, which moves it into the sensor's frame.
sim::VirtualScan DepthCameraScan(const Scene& scene, const std::filesystem::path& folder,
                                 std::uint64_t seed) {
  const sim::DepthScan depth =
      sim::ScanWithDepthCamera(scene.objects, scene.T_W_C, sim::DepthCameraOptions{}, seed);
  sim::VirtualScan scan;
  if (depth.points_C.empty()) return scan;
  Eigen::Isometry3d T_file_C = Eigen::Isometry3d::Identity();
  T_file_C.linear() = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  std::vector<Eigen::Vector3d> points_file;
  points_file.reserve(depth.points_C.size());
  for (const Eigen::Vector3d& p_C : depth.points_C) points_file.push_back(T_file_C * p_C);
  const std::filesystem::path path = folder / "depth_scan.pcd";
  perception::WriteCloud(path, perception::MakeCloud(points_file), true, T_file_C);
  const mapping::ScanFile file = mapping::ReadScanFile(path);
  for (std::size_t i = 0; i < file.cloud.size(); ++i) {
    scan.points_C.push_back(file.cloud.Point(i));
    scan.object_index.push_back(depth.object_index[file.rows[i]]);
  }
  return scan;
}

// What the bench scores poses against: the physical object's declared symmetries (none for the
// CAD parts: what the database finds from a mesh is not a truth to score it against, so they are
// scored by ADD-S, PoseRight) and its mesh-taught model's points (every 4th), the same for every
// condition.
struct Truth {
  std::vector<perception::SymmetryAxis> symmetries;
  bool symmetries_declared = false;
  std::vector<Eigen::Vector3d> points_O;
  Eigen::Vector3d centre_O;
};

// A pose right within 5 mm and 2 degrees modulo the declared symmetries; for a part with none
// declared (the CAD parts), one whose model points each lie, on average, within 5 mm of the truly
// posed model's nearest point (ADD-S), which a pose related by any true symmetry passes and no
// symmetry that is not there does.
bool PoseRight(const Eigen::Isometry3d& T_S_O, const Eigen::Isometry3d& T_S_O_true,
               const perception::SymmetricPoseError& e, const Truth& truth) {
  if (truth.symmetries_declared) return e.rotation_rad <= 2.0 * kDeg && e.translation_m <= 0.005;
  const perception::PointCloud model = perception::MakeCloud(truth.points_O);
  return SymmetricSurfaceError(model, model, T_S_O, T_S_O_true) <= 0.005;
}

Truth TruthOf(const ObjectSource& object, const ObjectDatabase& db) {
  Truth truth;
  truth.symmetries = object.symmetries.value_or(std::vector<perception::SymmetryAxis>{});
  truth.symmetries_declared = object.symmetries.has_value();
  for (const perception::ObjectModel& m : db.objects) {
    if (m.id != object.id) continue;
    for (std::size_t i = 0; i < m.model.size(); i += 4) truth.points_O.push_back(m.model.Point(i));
    truth.centre_O = m.model.origin;
  }
  return truth;
}

// The database's model of `id` (every scene's object is in its condition's database).
const perception::ObjectModel& ModelNamed(const ObjectDatabase& db, const std::string& id) {
  const auto model = std::find_if(db.objects.begin(), db.objects.end(),
                                  [&](const perception::ObjectModel& o) { return o.id == id; });
  if (model == db.objects.end()) throw Error("recognition conditions: no model of " + id);
  return *model;
}

// One database and what recognition derives from it once, for every scan.
struct Recogniser {
  const ObjectDatabase& db;
  perception::RecognitionCache cache;
  explicit Recogniser(const ObjectDatabase& database) : db(database), cache(database) {}
};

// Recognises `scan` of `scene` and adds the outcome for its object (index 1) to `figures`, when
// the scan holds enough of it.
void ScoreScan(int scene_index, const Scene& scene, const sim::VirtualScan& scan,
               Recogniser& recogniser, const Truth& truth,
               const RecognitionConditionsOptions& options, ConditionFigures& figures) {
  const int visible =
      static_cast<int>(std::count(scan.object_index.begin(), scan.object_index.end(), 1));
  if (visible < kMinVisiblePoints) return;
  perception::RecognitionOptions recognition;
  recognition.seed = options.seed;
  recognition.threads = options.threads;
  const auto start = std::chrono::steady_clock::now();
  const perception::RecognitionResult answer = perception::RecognizeObjects(
      perception::MakeCloud(scan.points_C), recogniser.db, recogniser.cache, recognition);
  figures.seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++figures.scans;
  ++figures.objects;
  const perception::RecognizedObject* best = nullptr;
  int best_count = 0;
  for (const perception::RecognizedObject& o : answer.objects) {
    int count = 0;
    for (std::size_t i : o.segment) count += scan.object_index[i] == 1;
    if (count > best_count) best_count = count, best = &o;
  }
  if (best == nullptr || best->object_id != scene.id) return;
  ++figures.recognised;
  const Eigen::Isometry3d T_S_O_true = scene.T_W_C.inverse() * scene.T_W_O;
  const perception::SymmetricPoseError e = perception::PoseErrorModuloSymmetry(
      best->T_S_O, T_S_O_true, truth.points_O, truth.symmetries);
  ConditionPose pose;
  pose.scene = scene_index;
  pose.object = scene.id;
  pose.rotation_rad = e.rotation_rad;
  pose.translation_m = e.translation_m;
  pose.right = PoseRight(best->T_S_O, T_S_O_true, e, truth);
  pose.strict = e.rotation_rad <= 2.0 * kDeg && e.translation_m <= 0.005;
  const perception::ObjectModel& model = ModelNamed(recogniser.db, scene.id);
  pose.right_or_reported =
      pose.strict ||
      PosedButForWhatIsReported(perception::PoseErrorModuloSymmetry(
                                    best->T_S_O, T_S_O_true, truth.points_O, model.symmetries),
                                best->T_S_O, T_S_O_true, truth.points_O, model, *best);
  pose.equivalent_poses = static_cast<int>(best->equivalent_poses_S.size());
  if (e.rotation_rad < 10.0 * kDeg && e.translation_m < 0.05) {
    pose.nees_per_dimension = PoseNeesPerPinnedDirection(best->T_S_O, e.T_symmetric, truth.centre_O,
                                                         best->covariance, best->free_directions);
    if (pose.nees_per_dimension) figures.nees_per_dimension.push_back(*pose.nees_per_dimension);
  }
  figures.pose_success += pose.right;
  figures.pose_strict += pose.strict;
  figures.pose_or_reported += pose.right_or_reported;
  figures.poses.push_back(pose);
}

}  // namespace

void RecognitionConditionsOptions::Check() const {
  const OptionChecks check("RecognitionConditionsOptions");
  check.AtLeast("scans", scans, 1);
  check.AtLeast("views", views, 1);
  check.AtLeast("threads", threads, 1);
}

RecognitionConditions RunRecognitionConditions(const RecognitionConditionsOptions& options,
                                               const Progress& progress) {
  options.Check();
  const ScratchFolder folder("recognition-conditions");
  std::vector<ObjectSource> meshes, clouds;
  for (const char* name : kObjects) {
    meshes.push_back(perception::CatalogueObject(name));
    clouds.push_back(ScannedObject(name, meshes.back().mesh, folder.path(), options.seed));
  }
  std::vector<ObjectSource> flat = meshes;
  flat.push_back(perception::CatalogueObject("panel"));
  std::vector<ObjectSource> cad, cad_scans;
  for (const char* name : kCadMeshes) {
    cad.push_back(CadObject(options.data_cache, name, folder.path()));
    cad_scans.push_back(ScannedObject(name, cad.back().mesh, folder.path(), options.seed, 0.001));
  }

  sim::VirtualScannerOptions scan_options;
  scan_options.pattern.kind = scanner::ScannerKind::kGalvo;
  scan_options.pattern.galvo.step_stride = 2;
  scan_options.table_cache = options.table_cache;
  const sim::VirtualScanner scanner(scanner::DefaultScanner(scanner::ScannerKind::kGalvo),
                                    scan_options);
  perception::DatabaseBuildOptions build;
  build.views = options.views;
  build.seed = options.seed;
  build.threads = options.threads;
  auto database = [&](const std::vector<ObjectSource>& sources, const char* name) {
    return perception::BuildObjectDatabase(sources, scanner, build, [&](double f) {
      if (progress) progress(std::string("database of ") + name, f);
    });
  };
  const ObjectDatabase mesh_db = database(meshes, "meshes");
  const ObjectDatabase cloud_db = database(clouds, "scans");
  const ObjectDatabase flat_db = database(flat, "meshes and a panel");
  const ObjectDatabase cad_db = database(cad, "CAD parts in millimetres");
  const ObjectDatabase cad_scan_db = database(cad_scans, "scans of the CAD parts in millimetres");

  Recogniser from_meshes(mesh_db), from_scans(cloud_db), with_panel(flat_db), from_cad(cad_db),
      from_cad_scans(cad_scan_db);
  std::vector<Truth> truths, cad_truths;
  for (const ObjectSource& object : meshes) truths.push_back(TruthOf(object, mesh_db));
  for (const ObjectSource& object : cad) cad_truths.push_back(TruthOf(object, cad_db));
  const Truth panel_truth = TruthOf(flat.back(), flat_db);

  RecognitionConditions result;
  std::mt19937_64 rng(options.seed * 104729 + 17);
  std::mt19937_64 cad_rng(options.seed * 104729 + 29);  // the other conditions' scenes unchanged
  for (int s = 0; s < options.scans; ++s) {
    const std::size_t k = static_cast<std::size_t>(s) % meshes.size();
    const std::uint64_t scan_seed = options.seed + 31 * static_cast<std::uint64_t>(s);
    const Scene scene = ObjectScene(meshes[k], rng);
    const sim::VirtualScan scan = scanner.Scan(scene.objects, scene.T_W_C, scan_seed);
    ScoreScan(s, scene, scan, from_meshes, truths[k], options, result["mesh_models"]);
    ScoreScan(s, scene, scan, from_scans, truths[k], options, result["cloud_models"]);
    ScoreScan(s, scene, DepthCameraScan(scene, folder.path(), scan_seed), from_meshes, truths[k],
              options, result["depth_camera"]);
    const std::size_t c = static_cast<std::size_t>(s) % cad.size();
    const Scene cad_scene = ObjectScene(cad[c], cad_rng);
    const sim::VirtualScan cad_scan = scanner.Scan(cad_scene.objects, cad_scene.T_W_C, scan_seed);
    ScoreScan(s, cad_scene, cad_scan, from_cad, cad_truths[c], options, result["catalogue_mm"]);
    ScoreScan(s, cad_scene, cad_scan, from_cad_scans, cad_truths[c], options,
              result["catalogue_mm_clouds"]);
    const Scene panel = PanelScene(flat.back(), s, rng);
    ScoreScan(s, panel, scanner.Scan(panel.objects, panel.T_W_C, scan_seed), with_panel,
              panel_truth, options, result["flat_objects"]);
    if (progress) progress("scans", static_cast<double>(s + 1) / options.scans);
  }
  return result;
}

}  // namespace uwscan::bench
