#include "bench/recognition/recognition_benchmark.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <string>

#include "bench/recognition/pose_nees.hpp"
#include "bench/recognition/recognition_peers.hpp"
#include "bench/recognition/recognition_scan_cache.hpp"
#include "bench/recognition/reported_ambiguity.hpp"
#include "perception/preprocessing/normals.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_pose_search.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "perception/recognition/pose_check.hpp"
#include "scanner/common/fnv1a.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::bench {
namespace {

namespace sim = scanner::sim;
using perception::ObjectDatabase;
using perception::ObjectModel;
using perception::PointCloud;

constexpr double kDeg = std::numbers::pi / 180.0;
// The catalogue objects the bench's scenes are drawn from, in the order that draws them: the six
// the bench was first run with, so that its scans stay the same as the catalogue grows.
constexpr const char* kBenchObjects[] = {"elbow", "flange",      "pipe",
                                         "tee",   "valve_lever", "valve_wheel"};
constexpr const char* kForeignMeshes[] = {"bunny00", "rotor", "turbine", "anchor", "joint"};
constexpr int kMinVisiblePoints = 300;  // an object with fewer scan points is not scored

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The pose resting an object on the seabed (z = 0, up +z): its y_O up (valve stems), its z_O
// axis horizontal at `yaw_rad`, at (x, y), lowest vertex on the seabed.
Eigen::Isometry3d RestingPose(const scanner::TriangleMesh& mesh, double yaw_rad, double x,
                              double y) {
  Eigen::Matrix3d lay;
  lay << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // x_O -> x, y_O -> z, z_O -> -y
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * lay;
  double lowest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& v : mesh.vertices) lowest = std::min(lowest, (T.linear() * v).z());
  T.translation() = Eigen::Vector3d(x, y, -lowest);
  return T;
}

sim::SceneObject Object(const std::string& name, const scanner::TriangleMesh& mesh,
                        const Eigen::Isometry3d& T_W_O) {
  sim::SceneObject o;
  o.name = name;
  o.shape = sim::ObjectShape::kMesh;
  o.mesh = mesh;
  o.T_W_O = T_W_O;
  o.reflectance = 0.5;
  return o;
}

struct Scene {
  std::vector<sim::SceneObject> objects;  // [0] seabed, then catalogue objects, then foreign
  std::vector<std::string> classes;       // per object: catalogue id, "foreign" or "" (seabed)
  Eigen::Isometry3d T_W_C;
};

Scene MakeScene(int index, const std::vector<perception::ObjectSource>& catalogue,
                const std::vector<scanner::TriangleMesh>& foreign, std::uint64_t seed) {
  std::mt19937_64 rng(seed * 7919 + static_cast<std::uint64_t>(index));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Scene scene;
  sim::SceneObject seabed;
  seabed.name = "seabed";
  seabed.shape = sim::ObjectShape::kPlane;
  seabed.mesh = sim::MakeRectangle(4.0, 4.0);
  seabed.reflectance = 0.3;
  scene.objects.push_back(seabed);
  scene.classes.push_back("");
  // The target, in turn through the catalogue; a second catalogue object in half the scenes,
  // touching the first in a third of those; a foreign mesh nearby.
  const std::size_t first = static_cast<std::size_t>(index) % catalogue.size();
  std::vector<std::pair<std::size_t, Eigen::Vector2d>> placed = {{first, {0.0, 0.0}}};
  if (unit(rng) < 0.5) {
    const std::size_t second =
        (first + 1 + static_cast<std::size_t>(unit(rng) * (catalogue.size() - 1))) %
        catalogue.size();
    const double touching = unit(rng) < 0.33;
    const double gap = 0.5 *
                       (catalogue[first].mesh.BoundingBoxDiagonal() +
                        catalogue[second].mesh.BoundingBoxDiagonal()) *
                       (touching ? 0.55 : 1.0);
    const double angle = 2.0 * std::numbers::pi * unit(rng);
    placed.push_back({second, gap * Eigen::Vector2d(std::cos(angle), std::sin(angle))});
  }
  for (const auto& [k, xy] : placed) {
    scene.objects.push_back(
        Object(catalogue[k].id, catalogue[k].mesh,
               RestingPose(catalogue[k].mesh, 2.0 * std::numbers::pi * unit(rng), xy.x(), xy.y())));
    scene.classes.push_back(catalogue[k].id);
  }
  if (!foreign.empty()) {
    const scanner::TriangleMesh& mesh = foreign[static_cast<std::size_t>(index) % foreign.size()];
    const double angle = 2.0 * std::numbers::pi * unit(rng);
    const double distance = 0.25 + 0.5 * catalogue[first].mesh.BoundingBoxDiagonal();
    scene.objects.push_back(
        Object("foreign", mesh,
               RestingPose(mesh, 2.0 * std::numbers::pi * unit(rng), distance * std::cos(angle),
                           distance * std::sin(angle))));
    scene.classes.push_back("foreign");
  }
  // The camera 0.5-1.5 m from the target, 35-90 degrees above the seabed.
  const double range = 0.5 + unit(rng);
  const double elevation = (35.0 + 55.0 * unit(rng)) * kDeg;
  const double azimuth = 2.0 * std::numbers::pi * unit(rng);
  const Eigen::Vector3d target = scene.objects[1].T_W_O.translation();
  const Eigen::Vector3d eye =
      target + range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                       std::cos(elevation) * std::sin(azimuth),
                                       std::sin(elevation));
  const Eigen::Vector3d up =
      std::abs(std::sin(elevation)) > 0.99 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
  scene.T_W_C = sim::LookAt(eye, target, up);
  return scene;
}

// The database's models as the peers take them, with the views scanned again for their points.
std::vector<PeerObject> PeerObjects(const ObjectDatabase& db,
                                    const std::vector<perception::ObjectSource>& catalogue,
                                    const sim::VirtualScanner& scanner, std::uint64_t seed,
                                    int threads) {
  std::vector<PeerObject> peers(db.objects.size());
  for (std::size_t k = 0; k < db.objects.size(); ++k) {
    peers[k].id = db.objects[k].id;
    peers[k].model = db.objects[k].model;
    const std::vector<sim::SceneObject> scene = {
        Object(catalogue[k].id, catalogue[k].mesh, Eigen::Isometry3d::Identity())};
    std::vector<std::optional<PeerView>> views(db.objects[k].views.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int v = 0; v < static_cast<int>(views.size()); ++v) {
      const Eigen::Isometry3d T_O_C = db.objects[k].views[static_cast<std::size_t>(v)].T_O_C;
      const sim::VirtualScan scan =
          scanner.Scan(scene, T_O_C, seed + static_cast<std::uint64_t>(v));
      const PointCloud cloud =
          perception::VoxelDownsample(perception::MakeCloud(scan.points_C),
                                      perception::VoxelFilterOptions{db.parameters.voxel_m});
      perception::EsfResult esf;
#pragma omp critical(pcl_esf)
      esf = perception::ComputePclEsf(cloud);  // PCL's ESF uses the global rand()
      if (!esf.ok) continue;
      PeerView view{esf.histogram, T_O_C, Eigen::Vector3d::Zero()};
      for (std::size_t i = 0; i < cloud.size(); ++i) view.centroid_C += cloud.Point(i);
      view.centroid_C /= static_cast<double>(cloud.size());
      views[static_cast<std::size_t>(v)] = view;
    }
    for (const auto& v : views) {
      if (v) peers[k].views.push_back(*v);
    }
  }
  return peers;
}

// The database's model named `id`, or none (a foreign mesh).
const ObjectModel* ModelNamed(const ObjectDatabase& db, const std::string& id) {
  const auto model = std::find_if(db.objects.begin(), db.objects.end(),
                                  [&](const ObjectModel& o) { return o.id == id; });
  return model == db.objects.end() ? nullptr : &*model;
}

// The model points pose errors are measured on (every 4th).
std::vector<Eigen::Vector3d> ErrorPoints(const ObjectModel& model) {
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < model.model.size(); i += 4) points.push_back(model.model.Point(i));
  return points;
}

// The pose error modulo symmetry (rotation rad, translation m) of a candidate for a true object
// `truth`; (-1, -1) when the candidate is another object's, was never posed, or `truth` is not
// in the database (a foreign mesh).
std::pair<double, double> CandidateError(const perception::RecognitionCandidate& c,
                                         const std::string& truth,
                                         const Eigen::Isometry3d& T_S_O_true,
                                         const ObjectDatabase& db) {
  const ObjectModel* model = ModelNamed(db, truth);
  if (model == nullptr || c.object_id != truth || c.fitness <= 0.0) return {-1.0, -1.0};
  const perception::SymmetricPoseError e = perception::PoseErrorModuloSymmetry(
      c.T_S_O, T_S_O_true, ErrorPoints(*model), model->symmetries);
  return {e.rotation_rad, e.translation_m};
}

// ObjectOutcome::why_wrong of a wrong answer `ours`, given the true object checked at its true
// pose on the same segment.
std::string WhyWrong(const perception::RecognitionCandidate& truth,
                     const perception::RecognizedObject& ours, double score_tie) {
  if (!truth.verified) return "unverified";
  if (ours.object_id == "unknown" || truth.score > ours.score + score_tie) return "missed";
  if (truth.score < ours.score - score_tie) return "outscored";
  return "tie";
}

// Scores one answer for a true object; `T_S_O_true` is the truth in the scan frame. Returns
// the pose error modulo symmetry when the answer is right.
// `reported`: uwscan's answer, for its equivalent poses and free slides (none for the peers).
std::optional<perception::SymmetricPoseError> Score(
    const std::string& truth, const std::string& answer,
    const std::optional<Eigen::Isometry3d>& T_S_O, const Eigen::Isometry3d& T_S_O_true,
    const ObjectDatabase& db, PipelineFigures& figures,
    const perception::RecognizedObject* reported = nullptr) {
  figures.confusion[truth][answer] += 1;
  if (truth == "foreign") {
    ++figures.foreign;
    if (answer == "unknown") ++figures.foreign_unknown;
    return std::nullopt;
  }
  ++figures.objects;
  const bool reported_as_equivalent =
      reported != nullptr &&
      std::any_of(reported->equivalent_objects_S.begin(), reported->equivalent_objects_S.end(),
                  [&](const auto& e) { return e.first == truth; });
  if (answer != truth || !T_S_O) {
    figures.recognised_or_reported += reported_as_equivalent;
    return std::nullopt;
  }
  ++figures.recognised;
  ++figures.recognised_or_reported;
  const ObjectModel& model = *ModelNamed(db, truth);  // answers come from the database
  const std::vector<Eigen::Vector3d> points = ErrorPoints(model);
  const perception::SymmetricPoseError e =
      perception::PoseErrorModuloSymmetry(*T_S_O, T_S_O_true, points, model.symmetries);
  figures.rotation_errors_rad.push_back(e.rotation_rad);
  figures.translation_errors_m.push_back(e.translation_m);
  const bool posed = e.rotation_rad <= 2.0 * kDeg && e.translation_m <= 0.005;
  figures.pose_success += posed;
  figures.pose_or_reported +=
      posed || (reported != nullptr &&
                PosedButForWhatIsReported(e, *T_S_O, T_S_O_true, points, model, *reported));
  if (e.mssd_m < 0.1 * model.diameter_m) ++figures.mssd_success;
  if (reported != nullptr && e.rotation_rad < 10.0 * kDeg && e.translation_m < 0.05) {
    if (const auto nees =
            PoseNeesPerPinnedDirection(*T_S_O, e.T_symmetric, model.model.origin,
                                       reported->covariance, reported->free_directions)) {
      figures.pose_nees_per_dimension.push_back(*nees);
      figures.pose_nees_by_class[truth].push_back(*nees);
    }
  }
  if (model.grasps.empty()) return e;
  const Eigen::Isometry3d& T_true = e.T_symmetric;
  double worst_position = 0.0, worst_angle = 0.0;
  for (const perception::GraspFrame& g : model.grasps) {
    const Eigen::Isometry3d est = *T_S_O * g.T_O_G, truth_g = T_true * g.T_O_G;
    worst_position = std::max(worst_position, (est.translation() - truth_g.translation()).norm());
    const double c = std::clamp(est.linear().col(2).dot(truth_g.linear().col(2)), -1.0, 1.0);
    worst_angle = std::max(worst_angle, std::acos(c));
  }
  figures.grasp_position_errors_m.push_back(worst_position);
  figures.grasp_angle_errors_rad.push_back(worst_angle);
  if (worst_position <= 0.005 && worst_angle <= 3.0 * kDeg) ++figures.grasp_success;
  return e;
}

// What decides scan `s` of the bench: the simulator's code, its scene (objects, meshes, poses),
// the camera, the noise seed and the rendering settings.
CachedScanKey KeyOf(const Scene& scene, int s, const RecognitionBenchOptions& options) {
  std::string bytes = kSimulatorSourceHash;
  auto add = [&bytes](const auto* data, std::size_t count) {
    bytes.append(reinterpret_cast<const char*>(data), count * sizeof(*data));
  };
  for (const sim::SceneObject& o : scene.objects) {
    bytes += o.name;
    add(o.T_W_O.matrix().data(), 16);
    add(&o.reflectance, 1);
    for (const Eigen::Vector3d& v : o.mesh.vertices) add(v.data(), 3);
    for (const auto& t : o.mesh.triangles) add(t.data(), t.size());
  }
  add(scene.T_W_C.matrix().data(), 16);
  const std::uint64_t seed = options.seed;
  const int settings[] = {s, options.images ? 1 : 0, options.galvo_stride};
  add(&seed, 1);
  add(settings, 3);
  return {s, Fnv1a64(bytes.data(), bytes.size())};
}

// Scan `s` of the bench, from the scan cache when it holds it (then saved there).
sim::VirtualScan ScanOf(const Scene& scene, int s, const sim::VirtualScanner& scanner,
                        const RecognitionBenchOptions& options) {
  const CachedScanKey key = KeyOf(scene, s, options);
  if (!options.scan_cache.empty()) {
    if (std::optional<sim::VirtualScan> cached = LoadCachedScan(options.scan_cache, key))
      return std::move(*cached);
  }
  sim::VirtualScan scan =
      scanner.Scan(scene.objects, scene.T_W_C, options.seed + 1000 + static_cast<std::uint64_t>(s));
  if (!options.scan_cache.empty()) SaveCachedScan(options.scan_cache, key, scan);
  return scan;
}

// The foreign meshes, scaled to 0.25 m across: objects the database does not hold.
std::vector<scanner::TriangleMesh> ForeignMeshes(const std::filesystem::path& data_cache) {
  std::vector<scanner::TriangleMesh> foreign;
  for (const char* name : kForeignMeshes) {
    scanner::TriangleMesh mesh =
        scanner::LoadMesh(data_cache / "meshes" / (std::string(name) + ".off"));
    const double scale = 0.25 / mesh.BoundingBoxDiagonal();
    for (Eigen::Vector3d& v : mesh.vertices) v *= scale;
    foreign.push_back(std::move(mesh));
  }
  return foreign;
}

// The scenes' scanner: the database's, with rendered and detected frames when asked, in water
// that attenuates.
sim::VirtualScannerOptions SceneScanOptions(sim::VirtualScannerOptions scan, bool images) {
  if (images) {
    sim::SimulationEffects& e = scan.effects;
    e.peak_noise.on = false;
    e.image.on = e.beam.on = e.sensor_noise.on = e.speckle.on = e.backscatter.on = e.ambient.on =
        true;
    e.attenuation = true;
  }
  sim::Water water;
  water.attenuation_per_m = 0.2;
  scan.water = water;
  return scan;
}

// What every scan of a run is recognised and scored with, and where the figures go.
struct BenchRun {
  const RecognitionBenchOptions& options;
  const ObjectDatabase& db;
  perception::RecognitionCache& cache;
  const perception::RecognitionOptions& recognition;
  const std::optional<PclEsfPeer>& pcl_peer;
  const std::optional<PpfPeer>& ppf_peer;
  RecognitionBenchResult& result;
};

// The segment of `answer` holding most of object `o`'s scan points: its index (-1 for none) and
// that count.
std::pair<int, int> BestSegment(const sim::VirtualScan& scan,
                                const perception::RecognitionResult& answer, std::size_t o) {
  int best_segment = -1, best_count = 0;
  for (std::size_t k = 0; k < answer.objects.size(); ++k) {
    int count = 0;
    for (std::size_t i : answer.objects[k].segment)
      count += scan.object_index[i] == static_cast<int>(o);
    if (count > best_count) best_count = count, best_segment = static_cast<int>(k);
  }
  return {best_segment, best_count};
}

// An object no segment holds: every pipeline answered "unknown" for it.
void ScoreUnseen(BenchRun& run, int s, const std::string& truth, int visible,
                 const Eigen::Isometry3d& T_S_O_true) {
  ObjectOutcome outcome;
  outcome.scan = s;
  outcome.truth = truth;
  outcome.answer = "unknown";
  outcome.points = visible;
  if (truth != "foreign") outcome.why_wrong = "no segment";
  run.result.outcomes.push_back(std::move(outcome));
  Score(truth, "unknown", std::nullopt, T_S_O_true, run.db, run.result.pipelines["uwscan"]);
  if (!run.options.run_peers) return;
  Score(truth, "unknown", std::nullopt, T_S_O_true, run.db, run.result.pipelines["pcl_esf"]);
  if (run.ppf_peer)
    Score(truth, "unknown", std::nullopt, T_S_O_true, run.db, run.result.pipelines["opencv_ppf"]);
}

// uwscan's answer for an object (`ours`, the segment holding `best_count` of its `visible`
// points), before scoring.
ObjectOutcome OutcomeOf(int s, const std::string& truth, int visible, int best_count,
                        const perception::RecognizedObject& ours,
                        const Eigen::Isometry3d& T_S_O_true, const ObjectDatabase& db) {
  ObjectOutcome outcome;
  outcome.scan = s;
  outcome.truth = truth;
  outcome.answer = ours.object_id;
  outcome.points = visible;
  outcome.points_in_segment = best_count;
  outcome.segment_points = static_cast<int>(ours.segment.size());
  outcome.candidates = ours.candidates;
  outcome.equivalent_poses = static_cast<int>(ours.equivalent_poses_S.size());
  for (const auto& [id, T] : ours.equivalent_objects_S) outcome.equivalent_objects.push_back(id);
  for (const perception::RecognitionCandidate& c : ours.candidates) {
    outcome.candidate_errors.push_back(CandidateError(c, truth, T_S_O_true, db));
  }
  for (const perception::FreeDirection& f : ours.free_directions) {
    if (f.kind != perception::FreeKind::kUnconstrained) continue;
    ++(f.motion == perception::FreeMotion::kTranslation ? outcome.free_slides : outcome.free_turns);
  }
  return outcome;
}

// The peers on the segment uwscan answered for, voxelised as the database's views are.
void ScorePeers(BenchRun& run, const PointCloud& cloud, const std::vector<std::size_t>& segment_ids,
                const std::string& truth, const Eigen::Isometry3d& T_S_O_true) {
  const PointCloud segment =
      perception::VoxelDownsample(perception::Subset(cloud, segment_ids),
                                  perception::VoxelFilterOptions{run.db.parameters.voxel_m});
  auto start = std::chrono::steady_clock::now();
  const PeerAnswer pcl = run.pcl_peer->Recognize(segment);
  run.result.pipelines["pcl_esf"].seconds += Seconds(start);
  Score(truth, pcl.id, pcl.T_S_O, T_S_O_true, run.db, run.result.pipelines["pcl_esf"]);
  if (!run.ppf_peer) return;
  start = std::chrono::steady_clock::now();
  perception::NormalOptions normals;
  normals.radius_m = run.db.parameters.normal_radius_m;
  normals.threads = run.options.threads;
  const perception::CloudWithNormals with_normals =
      perception::AttachNormals(segment, perception::EstimateNormals(segment, normals));
  const PeerAnswer ppf = run.ppf_peer->Recognize(with_normals.cloud);
  run.result.pipelines["opencv_ppf"].seconds += Seconds(start);
  Score(truth, ppf.id, ppf.T_S_O, T_S_O_true, run.db, run.result.pipelines["opencv_ppf"]);
}

// Object `o` of scan `s`: uwscan's answer for the segment holding most of it, scored, why it was
// wrong when it was, and the peers' answers on that segment.
void ScoreObject(BenchRun& run, int s, const Scene& scene, const sim::VirtualScan& scan,
                 const PointCloud& cloud, const perception::RecognitionResult& answer,
                 std::size_t o) {
  int visible = 0;
  for (std::int32_t id : scan.object_index) visible += id == static_cast<int>(o);
  if (visible < kMinVisiblePoints) return;
  const auto [best_segment, best_count] = BestSegment(scan, answer, o);
  const Eigen::Isometry3d T_S_O_true = scene.T_W_C.inverse() * scene.objects[o].T_W_O;
  const std::string& truth = scene.classes[o];
  if (best_segment < 0) {
    ScoreUnseen(run, s, truth, visible, T_S_O_true);
    return;
  }
  const perception::RecognizedObject& ours = answer.objects[static_cast<std::size_t>(best_segment)];
  ObjectOutcome outcome = OutcomeOf(s, truth, visible, best_count, ours, T_S_O_true, run.db);
  if (const auto e = Score(truth, ours.object_id, ours.T_S_O, T_S_O_true, run.db,
                           run.result.pipelines["uwscan"], &ours)) {
    outcome.rotation_error_rad = e->rotation_rad;
    outcome.translation_error_m = e->translation_m;
  }
  if (ours.object_id != truth && truth != "foreign") {
    const perception::RecognitionCandidate checked = perception::CheckObjectPose(
        cloud, ours.segment, run.db, run.cache, truth, T_S_O_true, run.recognition);
    outcome.why_wrong = WhyWrong(checked, ours, run.recognition.score_tie);
    outcome.truth_check = checked;
  }
  run.result.outcomes.push_back(std::move(outcome));
  if (run.options.run_peers) ScorePeers(run, cloud, ours.segment, truth, T_S_O_true);
}

// Scan `s`: simulated (or read from the scan cache), recognised by uwscan, each object scored.
void RunScan(BenchRun& run, int s, const Scene& scene, const sim::VirtualScanner& scanner) {
  ++run.result.scans;
  auto start = std::chrono::steady_clock::now();
  const sim::VirtualScan scan = ScanOf(scene, s, scanner, run.options);
  run.result.simulation_seconds += Seconds(start);
  if (scan.points_C.empty()) return;
  const PointCloud cloud = perception::MakeCloud(scan.points_C);
  start = std::chrono::steady_clock::now();
  const perception::RecognitionResult answer =
      perception::RecognizeObjects(cloud, run.db, run.cache, run.recognition);
  PipelineFigures& uwscan = run.result.pipelines["uwscan"];
  uwscan.scan_seconds.push_back(Seconds(start));
  uwscan.seconds += uwscan.scan_seconds.back();
  for (const auto& [stage, seconds] : answer.stage_seconds)
    run.result.uwscan_stage_seconds[stage] += seconds;
  for (std::size_t o = 1; o < scene.objects.size(); ++o)
    ScoreObject(run, s, scene, scan, cloud, answer, o);
}

}  // namespace

void RecognitionBenchOptions::Check() const {
  const OptionChecks check("RecognitionBenchOptions");
  check.AtLeast("scans", scans, 1);
  check.AtLeast("views", views, 1);
  check.AtLeast("galvo_stride", galvo_stride, 1);
  check.AtLeast("threads", threads, 1);
}

RecognitionBenchResult RunRecognitionBench(const RecognitionBenchOptions& options,
                                           const Progress& progress) {
  options.Check();
  RecognitionBenchResult result;
  std::vector<perception::ObjectSource> catalogue;
  for (const char* name : kBenchObjects) catalogue.push_back(perception::CatalogueObject(name));
  const std::vector<scanner::TriangleMesh> foreign = ForeignMeshes(options.data_cache);

  sim::VirtualScannerOptions db_scan;
  db_scan.pattern.kind = scanner::ScannerKind::kGalvo;
  db_scan.pattern.galvo.step_stride = options.galvo_stride;
  db_scan.table_cache = options.table_cache;
  const scanner::Scanner galvo = scanner::DefaultScanner(scanner::ScannerKind::kGalvo);
  const sim::VirtualScanner db_scanner(galvo, db_scan);
  auto start = std::chrono::steady_clock::now();
  perception::DatabaseBuildOptions build;
  build.views = options.views;
  build.seed = options.seed;
  build.threads = options.threads;
  const ObjectDatabase db =
      perception::BuildObjectDatabase(catalogue, db_scanner, build, [&](double f) {
        if (progress) progress("object database", f);
      });
  result.database_seconds = Seconds(start);
  for (const perception::ObjectModel& o : db.objects) result.object_ids.push_back(o.id);

  const sim::VirtualScanner scene_scanner(galvo, SceneScanOptions(db_scan, options.images));

  std::optional<PclEsfPeer> pcl_peer;
  std::optional<PpfPeer> ppf_peer;
  if (options.run_peers) {
    std::vector<PeerObject> peers =
        PeerObjects(db, catalogue, db_scanner, options.seed, options.threads);
    if (options.run_ppf) {
      ppf_peer.emplace(peers);
      result.ppf_training_seconds = ppf_peer->training_seconds();
    }
    pcl_peer.emplace(std::move(peers));
  }

  perception::RecognitionCache cache(db);
  perception::RecognitionOptions recognition;
  recognition.seed = options.seed;
  recognition.threads = options.threads;
  BenchRun run{options, db, cache, recognition, pcl_peer, ppf_peer, result};
  for (int s = 0; s < options.scans; ++s) {
    if (options.only.empty() ||
        std::find(options.only.begin(), options.only.end(), s) != options.only.end()) {
      RunScan(run, s, MakeScene(s, catalogue, foreign, options.seed), scene_scanner);
    }
    if (progress) progress("scans", static_cast<double>(s + 1) / options.scans);
  }
  return result;
}

}  // namespace uwscan::bench
