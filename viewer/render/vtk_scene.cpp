#include "viewer/render/vtk_scene.hpp"

#include <vtkActor2D.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkEDLShading.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPointGaussianMapper.h>
#include <vtkPoints.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderStepsPass.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstdio>
#include <system_error>

#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "viewer/render/projection.hpp"
#include "viewer/scene/label_layout.hpp"
#include "viewer/scene/point_colours.hpp"

namespace uwscan::viewer::internal {
namespace {

constexpr double kTrajectoryLineWidthPx = 3.0;
constexpr double kEllipsoidOpacity = 0.35;
constexpr int kColourBarEntries = 256;
constexpr double kTrajectoryPointSizePx = 6.0;  // a vehicle that holds still is still seen
constexpr double kFitMargin = 0.9;              // of the tightest fit
constexpr int kLabelFontSizePx = 18;
constexpr double kLeaderLineWidthPx = 1.5;

void SetColour(vtkProperty& property, const Rgb& c) {
  property.SetColor(c.r / 255.0, c.g / 255.0, c.b / 255.0);
}

// A frame's three axes as lines of exact colours (x red, y green, z blue), unlit.
vtkSmartPointer<vtkActor> FrameActor(const FrameAxes& frame, const Eigen::Vector3d& anchor_W) {
  static const unsigned char kAxisColours[3][3] = {{230, 25, 25}, {25, 200, 25}, {40, 80, 255}};
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> lines;
  vtkNew<vtkUnsignedCharArray> colours;
  colours->SetNumberOfComponents(3);
  const Eigen::Vector3d origin = frame.T_W_F.translation() - anchor_W;
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d tip = origin + frame.length_m * frame.T_W_F.linear().col(a);
    const vtkIdType from = points->InsertNextPoint(origin.data());
    const vtkIdType to = points->InsertNextPoint(tip.data());
    const vtkIdType line[2] = {from, to};
    lines->InsertNextCell(2, line);
    colours->InsertNextTypedTuple(kAxisColours[a]);
  }
  vtkNew<vtkPolyData> data;
  data->SetPoints(points);
  data->SetLines(lines);
  data->GetCellData()->SetScalars(colours);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(data);
  mapper->SetColorModeToDirectScalars();
  mapper->SetScalarModeToUseCellData();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetLineWidth(kTrajectoryLineWidthPx);
  actor->GetProperty()->LightingOff();
  return actor;
}

// Text drawn over the 3-D scene, so no surface hides it; LabelLayout places it.
vtkSmartPointer<vtkTextActor> LabelActor(const Label& label) {
  auto actor = vtkSmartPointer<vtkTextActor>::New();
  actor->SetInput(label.text.c_str());
  actor->GetPositionCoordinate()->SetCoordinateSystemToDisplay();
  vtkTextProperty* text = actor->GetTextProperty();
  text->SetFontSize(kLabelFontSizePx);
  text->BoldOn();
  text->SetColor(label.colour.r / 255.0, label.colour.g / 255.0, label.colour.b / 255.0);
  // On a dark plate, so that it reads over an object of its own colour.
  text->SetBackgroundColor(0.05, 0.05, 0.05);
  text->SetBackgroundOpacity(0.8);
  text->SetJustificationToCentered();
  text->SetVerticalJustificationToCentered();
  return actor;
}

// Before every render, where the camera then looks from: each label placed near the point it
// names where it hides no other label and no named point (LayOutLabels), and a line from that
// point to the label. A label whose point is behind the camera or outside the picture is hidden.
// The renderer fills its window, so its display and viewport coordinates are the same.
class LabelLayout : public vtkCommand {
 public:
  static LabelLayout* New() { return new LabelLayout; }

  void Add(const Label& label) {
    points_W_.push_back(label.position_W);
    texts_.push_back(LabelActor(label));
    auto line = vtkSmartPointer<vtkActor2D>::New();
    line->SetMapper(vtkNew<vtkPolyDataMapper2D>());
    line->GetProperty()->SetColor(label.colour.r / 255.0, label.colour.g / 255.0,
                                  label.colour.b / 255.0);
    line->GetProperty()->SetLineWidth(kLeaderLineWidthPx);
    leaders_.push_back(line);
  }

  // The lines first, so that every label is drawn over them; then lays out before each render.
  void AttachTo(vtkRenderer& renderer, const Eigen::Vector3d& anchor_W) {
    anchor_W_ = anchor_W;
    for (vtkActor2D* line : leaders_) renderer.AddActor2D(line);
    for (vtkTextActor* text : texts_) renderer.AddActor2D(text);
    renderer.AddObserver(vtkCommand::StartEvent, this);
  }

  void Execute(vtkObject* caller, unsigned long /*event*/, void* /*data*/) override {
    auto* renderer = static_cast<vtkRenderer*>(caller);
    const int* size = renderer->GetSize();
    const Eigen::Vector2d picture(size[0], size[1]);
    const Eigen::Matrix4d ndc_from_world = NdcFromWorld(*renderer, anchor_W_);
    std::vector<std::size_t> shown;
    std::vector<LabelBox> boxes;
    for (std::size_t i = 0; i < texts_.size(); ++i) {
      const std::optional<Eigen::Vector2d> at = PixelOf(ndc_from_world, points_W_[i], picture);
      texts_[i]->SetVisibility(at.has_value());
      leaders_[i]->SetVisibility(at.has_value());
      if (!at) continue;
      double bbox[4] = {0.0, 0.0, 0.0, 0.0};  // x min, x max, y min, y max
      texts_[i]->GetBoundingBox(renderer, bbox);
      shown.push_back(i);
      boxes.push_back({*at, Eigen::Vector2d(bbox[1] - bbox[0], bbox[3] - bbox[2])});
    }
    const std::vector<Eigen::Vector2d> centres = LayOutLabels(boxes, picture);
    for (std::size_t k = 0; k < shown.size(); ++k) {
      texts_[shown[k]]->GetPositionCoordinate()->SetValue(centres[k].x(), centres[k].y());
      SetLeader(*leaders_[shown[k]], boxes[k], centres[k]);
    }
  }

 private:
  // Where a world point falls on the picture (sub-pixel, from its bottom left corner, as the
  // renderer's display coordinates count); std::nullopt behind the camera or outside the picture.
  static std::optional<Eigen::Vector2d> PixelOf(const Eigen::Matrix4d& ndc_from_world,
                                                const Eigen::Vector3d& p_W,
                                                const Eigen::Vector2d& picture) {
    const std::optional<Eigen::Vector2d> ndc = NdcOf(ndc_from_world, p_W);
    if (!ndc) return std::nullopt;
    return (0.5 * (ndc->array() + 1.0) * picture.array()).matrix();
  }

  // The line from the label's anchor to the nearest edge of its box; none when the box covers
  // its anchor.
  static void SetLeader(vtkActor2D& leader, const LabelBox& box, const Eigen::Vector2d& centre) {
    const Eigen::Vector2d half = 0.5 * box.size_px;
    const Eigen::Vector2d nearest = box.anchor_px.cwiseMax(centre - half).cwiseMin(centre + half);
    vtkNew<vtkPolyData> line;
    vtkNew<vtkPoints> points;
    vtkNew<vtkCellArray> cells;
    if ((nearest - box.anchor_px).norm() > 1.0) {
      points->InsertNextPoint(box.anchor_px.x(), box.anchor_px.y(), 0.0);
      points->InsertNextPoint(nearest.x(), nearest.y(), 0.0);
      const vtkIdType ends[2] = {0, 1};
      cells->InsertNextCell(2, ends);
    }
    line->SetPoints(points);
    line->SetLines(cells);
    static_cast<vtkPolyDataMapper2D*>(leader.GetMapper())->SetInputData(line);
  }

  Eigen::Vector3d anchor_W_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> points_W_;
  std::vector<vtkSmartPointer<vtkTextActor>> texts_;
  std::vector<vtkSmartPointer<vtkActor2D>> leaders_;
};

vtkSmartPointer<vtkPoints> FloatPoints(std::size_t n) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(static_cast<vtkIdType>(n));
  return points;
}

void AddCloud(const CloudLayer& layer, int layer_index, std::size_t stride,
              std::vector<float> scalars, const ScalarRange& range, const RenderOptions& options,
              VtkScene& out) {
  std::vector<Rgb> colours;
  colours.reserve(layer.size() / stride + 1);
  const bool ids = layer.object_ids.size() == layer.size();
  for (std::size_t i = 0, j = 0; i < layer.size(); i += stride, ++j) {
    colours.push_back(
        PointColour(options.colour, scalars.empty() ? 0.0f : scalars[j], range, layer_index,
                    ids ? std::optional<std::int32_t>(layer.object_ids[i]) : std::nullopt));
  }
  vtkSmartPointer<vtkPolyData> data =
      PointPolyData(layer.origin - out.anchor_W, layer.points, stride, colours);
  DrawnCloud drawn;
  drawn.actor = PointActor(data, options.point_size_px);
  drawn.layer = &layer;
  drawn.stride = stride;
  drawn.scalars = std::move(scalars);
  out.renderer->AddActor(drawn.actor);
  out.points_drawn += colours.size();
  out.clouds.push_back(std::move(drawn));
}

// A unit sphere stretched along the covariance's principal axes to `sigmas` deviations.
void AddEllipsoid(const UncertaintyEllipsoid& e, vtkPolyDataMapper* sphere, VtkScene& out) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(
      0.5 * (e.covariance_m2 + e.covariance_m2.transpose()));
  Eigen::Matrix3d axes = solver.eigenvectors();
  if (axes.determinant() < 0.0) axes.col(0) = -axes.col(0);
  const Eigen::Vector3d radii = e.sigmas * solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  const Eigen::Matrix3d M = axes * radii.asDiagonal();
  const Eigen::Vector3d centre = e.centre_W - out.anchor_W;
  vtkNew<vtkMatrix4x4> matrix;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) matrix->SetElement(r, c, M(r, c));
    matrix->SetElement(r, 3, centre[r]);
  }
  vtkNew<vtkActor> actor;
  actor->SetMapper(sphere);
  actor->SetUserMatrix(matrix);
  SetColour(*actor->GetProperty(), e.colour);
  actor->GetProperty()->SetOpacity(kEllipsoidOpacity);
  out.renderer->AddActor(actor);
}

std::string BarTitle(ColourMode mode) {
  switch (mode) {
    case ColourMode::kHeight:
      return "height m";
    case ColourMode::kError:
      return "error m";
    case ColourMode::kIntensity:
      return "intensity";
    case ColourMode::kDeviation:
      return "deviation m";
    case ColourMode::kObject:
      break;
  }
  return "";
}

}  // namespace

vtkSmartPointer<vtkActor> MeshActor(const MeshLayer& layer, const Rgb& colour,
                                    const Eigen::Vector3d& anchor_W) {
  auto points = FloatPoints(layer.mesh.vertices.size());
  for (std::size_t i = 0; i < layer.mesh.vertices.size(); ++i) {
    const Eigen::Vector3d p = layer.T_W_M * layer.mesh.vertices[i] - anchor_W;
    points->SetPoint(static_cast<vtkIdType>(i), p.x(), p.y(), p.z());
  }
  vtkNew<vtkCellArray> triangles;
  for (const Eigen::Vector3i& t : layer.mesh.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    triangles->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> data;
  data->SetPoints(points);
  data->SetPolys(triangles);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(data);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  SetColour(*actor->GetProperty(), colour);
  return actor;
}

vtkSmartPointer<vtkActor> TrajectoryActor(const TrajectoryLayer& layer, const Rgb& colour,
                                          const Eigen::Vector3d& anchor_W) {
  auto points = FloatPoints(layer.positions_W.size());
  vtkNew<vtkCellArray> line, vertices;
  line->InsertNextCell(static_cast<vtkIdType>(layer.positions_W.size()));
  for (std::size_t i = 0; i < layer.positions_W.size(); ++i) {
    const Eigen::Vector3d p = layer.positions_W[i] - anchor_W;
    points->SetPoint(static_cast<vtkIdType>(i), p.x(), p.y(), p.z());
    line->InsertCellPoint(static_cast<vtkIdType>(i));
  }
  // The first and last positions as dots: where the path starts and where the vehicle is.
  vertices->InsertNextCell(1);
  vertices->InsertCellPoint(0);
  vertices->InsertNextCell(1);
  vertices->InsertCellPoint(static_cast<vtkIdType>(layer.positions_W.size() - 1));
  vtkNew<vtkPolyData> data;
  data->SetPoints(points);
  data->SetLines(line);
  data->SetVerts(vertices);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(data);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  SetColour(*actor->GetProperty(), colour);
  actor->GetProperty()->SetLineWidth(kTrajectoryLineWidthPx);
  actor->GetProperty()->SetPointSize(kTrajectoryPointSizePx);
  actor->GetProperty()->LightingOff();  // the line keeps its exact colour
  return actor;
}

vtkSmartPointer<vtkPolyData> PointPolyData(const Eigen::Vector3d& origin_render,
                                           const std::vector<Eigen::Vector3f>& offsets,
                                           std::size_t stride, const std::vector<Rgb>& colours) {
  const std::size_t n = colours.size();
  vtkNew<vtkFloatArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(static_cast<vtkIdType>(n));
  float* out = xyz->WritePointer(0, static_cast<vtkIdType>(3 * n));
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetName("colour");
  rgb->SetNumberOfComponents(3);
  rgb->SetNumberOfTuples(static_cast<vtkIdType>(n));
  unsigned char* c = rgb->WritePointer(0, static_cast<vtkIdType>(3 * n));
  for (std::size_t j = 0; j < n; ++j) {
    // The offset is added in double: the origin may be far from the render anchor.
    const Eigen::Vector3d p = origin_render + offsets[j * stride].cast<double>();
    for (int a = 0; a < 3; ++a) out[3 * j + a] = static_cast<float>(p[a]);
    c[3 * j] = colours[j].r;
    c[3 * j + 1] = colours[j].g;
    c[3 * j + 2] = colours[j].b;
  }
  vtkNew<vtkPoints> points;
  points->SetData(xyz);
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(points);
  data->GetPointData()->SetScalars(rgb);
  return data;
}

vtkSmartPointer<vtkActor> PointActor(vtkPolyData* points, double point_size_px) {
  vtkNew<vtkPointGaussianMapper> mapper;
  mapper->SetInputData(points);
  mapper->SetScaleFactor(0.0);  // plain points of the actor's point size, not splats
  mapper->EmissiveOff();
  mapper->SetColorModeToDirectScalars();
  mapper->ScalarVisibilityOn();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetPointSize(static_cast<float>(point_size_px));
  actor->GetProperty()->LightingOff();
  return actor;
}

vtkSmartPointer<vtkScalarBarActor> ColourBar(const ScalarRange& range, const std::string& title,
                                             ColourMode mode) {
  vtkNew<vtkLookupTable> table;
  table->SetNumberOfTableValues(kColourBarEntries);
  table->SetRange(range.lo, range.hi);
  for (int i = 0; i < kColourBarEntries; ++i) {
    const double t = static_cast<double>(i) / (kColourBarEntries - 1);
    const Rgb c = mode == ColourMode::kDeviation ? DivergingColour(t) : ContinuousColour(t);
    table->SetTableValue(i, c.r / 255.0, c.g / 255.0, c.b / 255.0, 1.0);
  }
  auto bar = vtkSmartPointer<vtkScalarBarActor>::New();
  bar->SetLookupTable(table);
  bar->SetTitle(title.c_str());
  bar->SetNumberOfLabels(5);
  bar->SetLabelFormat("%-#7.3g");
  bar->SetPosition(0.88, 0.1);
  bar->SetWidth(0.1);
  bar->SetHeight(0.8);
  bar->UnconstrainedFontSizeOn();
  bar->GetTitleTextProperty()->SetFontSize(16);
  bar->GetLabelTextProperty()->SetFontSize(14);
  return bar;
}

void EnableEyeDomeLighting(vtkRenderer& renderer) {
  vtkNew<vtkRenderStepsPass> steps;
  vtkNew<vtkEDLShading> edl;
  edl->SetDelegatePass(steps);
  renderer.SetPass(edl);
}

VtkScene BuildVtkScene(const Scene& scene, const RenderOptions& options) {
  options.Check();
  VtkScene out;
  out.renderer = vtkSmartPointer<vtkRenderer>::New();
  out.renderer->SetBackground(options.background.r / 255.0, options.background.g / 255.0,
                              options.background.b / 255.0);
  out.anchor_W = scene.Anchor();
  out.points_total = scene.num_points();
  const std::size_t stride = PointStride(out.points_total, options.max_points);
  const Eigen::Vector3d up = options.up.normalized();

  std::vector<std::vector<float>> scalars;
  for (const CloudLayer& layer : scene.clouds)
    scalars.push_back(PointScalars(layer, options.colour, up, stride));
  const ScalarRange range = SceneRange(scalars, options);
  for (std::size_t i = 0; i < scene.clouds.size(); ++i) {
    AddCloud(scene.clouds[i], static_cast<int>(i), stride, std::move(scalars[i]), range, options,
             out);
  }
  // Meshes and trajectories continue the categorical colours after the clouds', so no two
  // things of one scene share a colour when clouds are coloured by file.
  std::vector<vtkActor*> fitted;
  for (const DrawnCloud& cloud : out.clouds) fitted.push_back(cloud.actor);
  int next_colour = static_cast<int>(scene.clouds.size());
  for (const MeshLayer& mesh : scene.meshes) {
    vtkSmartPointer<vtkActor> actor =
        MeshActor(mesh, CategoricalColour(next_colour++), out.anchor_W);
    out.renderer->AddActor(actor);
    fitted.push_back(actor);
  }
  out.fit_bounds = UnionBounds(fitted);
  for (const TrajectoryLayer& trajectory : scene.trajectories) {
    const Rgb colour = trajectory.colour.value_or(CategoricalColour(next_colour));
    ++next_colour;
    if (!trajectory.positions_W.empty())
      out.renderer->AddActor(TrajectoryActor(trajectory, colour, out.anchor_W));
  }
  if (!scene.ellipsoids.empty()) {
    vtkNew<vtkSphereSource> sphere;
    sphere->SetRadius(1.0);
    sphere->SetThetaResolution(24);
    sphere->SetPhiResolution(12);
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(sphere->GetOutputPort());
    for (const UncertaintyEllipsoid& e : scene.ellipsoids) AddEllipsoid(e, mapper, out);
  }
  for (const FrameAxes& frame : scene.frames) {
    if (!(frame.length_m > 0.0)) throw Error("frame " + frame.name + ": axis length must be > 0");
    out.renderer->AddActor(FrameActor(frame, out.anchor_W));
  }
  if (!scene.labels.empty()) {
    vtkNew<LabelLayout> layout;
    for (const Label& label : scene.labels) layout->Add(label);
    layout->AttachTo(*out.renderer, out.anchor_W);
  }
  if (IsContinuous(options.colour) && out.points_total > 0) {
    out.range = range;
    if (options.colour_bar)
      out.renderer->AddViewProp(ColourBar(range, BarTitle(options.colour), options.colour));
  }
  if (options.eye_dome_lighting) EnableEyeDomeLighting(*out.renderer);
  return out;
}

std::optional<std::array<double, 6>> UnionBounds(const std::vector<vtkActor*>& actors) {
  std::optional<std::array<double, 6>> all;
  for (vtkActor* actor : actors) {
    const double* b = actor->GetBounds();
    if (b == nullptr || !(b[0] <= b[1])) continue;
    if (!all) {
      all = std::array<double, 6>{b[0], b[1], b[2], b[3], b[4], b[5]};
      continue;
    }
    for (int a = 0; a < 3; ++a) {
      (*all)[2 * a] = std::min((*all)[2 * a], b[2 * a]);
      (*all)[2 * a + 1] = std::max((*all)[2 * a + 1], b[2 * a + 1]);
    }
  }
  return all;
}

void ApplyCameraPreset(vtkRenderer& renderer, CameraPreset preset, const Eigen::Vector3d& up_in,
                       const std::optional<std::array<double, 6>>& bounds) {
  const Eigen::Vector3d up = up_in.normalized();
  // A horizontal reference direction: x, unless x is (nearly) vertical.
  Eigen::Vector3d north = Eigen::Vector3d::UnitX() - up * up.x();
  if (north.norm() < 0.3) north = Eigen::Vector3d::UnitY() - up * up.y();
  north.normalize();
  const Eigen::Vector3d east = up.cross(north);
  Eigen::Vector3d towards_camera = up, view_up = up;
  switch (preset) {
    case CameraPreset::kTop:
      towards_camera = up;
      view_up = north;
      break;
    case CameraPreset::kSide:
      towards_camera = -east;
      break;
    case CameraPreset::kFit:
      towards_camera = (0.8 * up - 0.6 * north - 0.5 * east).normalized();
      break;
  }
  vtkCamera* camera = renderer.GetActiveCamera();
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  camera->SetPosition(towards_camera.x(), towards_camera.y(), towards_camera.z());
  camera->SetViewUp(view_up.x(), view_up.y(), view_up.z());
  // Keeps the direction; fits the visible props' projected box rather than their bounding
  // sphere, so the scene fills the picture. Needs the renderer in its window.
  if (bounds) {
    renderer.ResetCamera(bounds->data());
    renderer.ResetCameraScreenSpace(bounds->data());
  } else {
    renderer.ResetCamera();
    renderer.ResetCameraScreenSpace();
  }
  camera->Zoom(kFitMargin);
  renderer.ResetCameraClippingRange();
}

vtkSmartPointer<vtkRenderWindow> MakeRenderWindow(const RenderOptions& options, bool offscreen) {
  auto window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetSize(options.width_px, options.height_px);
  window->SetMultiSamples(0);
  if (offscreen) window->SetOffScreenRendering(1);
  return window;
}

void WriteWindowPng(vtkRenderWindow& window, const std::filesystem::path& path) {
  const std::filesystem::path folder = path.parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder)) {
    throw Error(path.string() + ": cannot write: folder '" + folder.string() + "' does not exist");
  }
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(&window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  const std::filesystem::path temporary = TemporaryBeside(path);
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(temporary.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  std::error_code ec;
  if (writer->GetErrorCode() != 0 || !std::filesystem::is_regular_file(temporary, ec)) {
    std::filesystem::remove(temporary, ec);
    throw Error(path.string() + ": cannot write the PNG (does the folder exist?)");
  }
  ReplaceWithTemporary(temporary, path);
}

Eigen::Matrix4d NdcFromWorld(vtkRenderer& renderer, const Eigen::Vector3d& anchor_W) {
  vtkMatrix4x4* m = renderer.GetActiveCamera()->GetCompositeProjectionTransformMatrix(
      renderer.GetTiledAspectRatio(), -1.0, 1.0);
  Eigen::Matrix4d ndc_from_render;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) ndc_from_render(r, c) = m->GetElement(r, c);
  }
  Eigen::Matrix4d render_from_world = Eigen::Matrix4d::Identity();
  render_from_world.block<3, 1>(0, 3) = -anchor_W;
  return ndc_from_render * render_from_world;
}

}  // namespace uwscan::viewer::internal
