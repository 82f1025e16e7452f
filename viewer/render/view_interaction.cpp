#include "viewer/render/view_interaction.hpp"

#include <vtkActor.h>
#include <vtkCommand.h>
#include <vtkObjectFactory.h>
#include <vtkPointPicker.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cstdio>

namespace uwscan::viewer::internal {
namespace {

constexpr double kPickTolerance = 0.005;  // of the window diagonal
constexpr double kMaxPointSizePx = 32.0;

// Holds what the pick observer needs; owned by the style, which the interactor keeps alive.
class PickObserver {
 public:
  std::function<void()> on_pick;
  void Picked(vtkObject*, unsigned long, void*) {
    if (on_pick) on_pick();
  }
};

}  // namespace

vtkStandardNewMacro(KeyStyle);

void KeyStyle::OnChar() {
  const char* sym = this->Interactor ? this->Interactor->GetKeySym() : nullptr;
  if (sym != nullptr && on_key && on_key(sym)) return;
  vtkInteractorStyleTrackballCamera::OnChar();
}

vtkSmartPointer<vtkTextActor> CornerText(const Rgb& background) {
  auto text = vtkSmartPointer<vtkTextActor>::New();
  text->SetDisplayPosition(10, 10);
  text->GetTextProperty()->SetFontSize(15);
  // Light text on a dark background, dark on a light one.
  const bool dark = background.r + background.g + background.b < 3 * 128;
  const double v = dark ? 0.92 : 0.08;
  text->GetTextProperty()->SetColor(v, v, v);
  return text;
}

std::string PickText(const DrawnCloud& cloud, std::size_t j, ColourMode colour) {
  const std::size_t i = j * cloud.stride;
  const Eigen::Vector3d p = cloud.layer->Point(i);
  char line[256];
  std::snprintf(line, sizeof line, "%s  point %zu  x %.4f  y %.4f  z %.4f m",
                cloud.layer->name.c_str(), i, p.x(), p.y(), p.z());
  std::string text = line;
  if (j < cloud.scalars.size()) {
    std::snprintf(line, sizeof line, "  %s %.6g%s", ToString(colour), cloud.scalars[j],
                  colour == ColourMode::kIntensity ? "" : " m");
    text += line;
  }
  if (i < cloud.layer->object_ids.size())
    text += "  object " + std::to_string(cloud.layer->object_ids[i]);
  return text;
}

void InstallViewControls(vtkRenderWindowInteractor& interactor, vtkRenderer& renderer,
                         const std::function<const std::vector<DrawnCloud>&()>& clouds,
                         ColourMode colour, RenderOptions& options, vtkTextActor& text) {
  vtkNew<KeyStyle> style;
  vtkNew<vtkPointPicker> picker;
  picker->SetTolerance(kPickTolerance);
  interactor.SetPicker(picker);

  auto observer = std::make_shared<PickObserver>();
  vtkPointPicker* raw_picker = picker;
  vtkTextActor* raw_text = &text;
  vtkRenderWindowInteractor* raw_interactor = &interactor;
  observer->on_pick = [raw_picker, raw_text, raw_interactor, clouds, colour] {
    const vtkIdType id = raw_picker->GetPointId();
    vtkActor* actor = raw_picker->GetActor();
    std::string message = "no point there";
    for (const DrawnCloud& cloud : clouds()) {
      if (id >= 0 && cloud.actor.GetPointer() == actor)
        message = PickText(cloud, static_cast<std::size_t>(id), colour);
    }
    raw_text->SetInput(message.c_str());
    raw_interactor->Render();
  };
  picker->AddObserver(vtkCommand::EndPickEvent, observer.get(), &PickObserver::Picked);

  vtkRenderer* raw_renderer = &renderer;
  RenderOptions* raw_options = &options;
  style->on_key = [raw_renderer, raw_options, raw_interactor, clouds,
                   observer](const std::string& key) {
    (void)observer;  // kept alive as long as the style
    RenderOptions& o = *raw_options;
    if (key == "f" || key == "t" || key == "s") {
      std::vector<vtkActor*> actors;
      for (const DrawnCloud& cloud : clouds()) actors.push_back(cloud.actor);
      const CameraPreset preset = key == "f"   ? CameraPreset::kFit
                                  : key == "t" ? CameraPreset::kTop
                                               : CameraPreset::kSide;
      ApplyCameraPreset(*raw_renderer, preset, o.up, UnionBounds(actors));
    } else if (key == "plus" || key == "minus" || key == "KP_Add" || key == "KP_Subtract") {
      const bool bigger = key == "plus" || key == "KP_Add";
      o.point_size_px = std::clamp(o.point_size_px + (bigger ? 1.0 : -1.0), 1.0, kMaxPointSizePx);
      for (const DrawnCloud& cloud : clouds())
        cloud.actor->GetProperty()->SetPointSize(static_cast<float>(o.point_size_px));
    } else if (key == "e") {
      o.eye_dome_lighting = !o.eye_dome_lighting;
      if (o.eye_dome_lighting) {
        EnableEyeDomeLighting(*raw_renderer);
      } else {
        raw_renderer->SetPass(nullptr);
      }
    } else {
      return false;
    }
    raw_interactor->Render();
    return true;
  };
  interactor.SetInteractorStyle(style);
}

}  // namespace uwscan::viewer::internal
