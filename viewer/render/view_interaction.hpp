#pragma once
// Internal to viewer/: what the interactive view and the live view share, the keys and the pick
// text. Includes VTK.

#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>

#include <functional>
#include <string>
#include <vector>

#include "viewer/render/vtk_scene.hpp"
#include "viewer/scene/render_options.hpp"

namespace uwscan::viewer::internal {

// Trackball camera whose character keys go to `on_key` first; keys it does not take keep VTK's
// meaning (p picks, q quits, r resets the camera).
class KeyStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static KeyStyle* New();
  vtkTypeMacro(KeyStyle, vtkInteractorStyleTrackballCamera)
      std::function<bool(const std::string& key)> on_key;
  void OnChar() override;
};

// The corner text that shows picked points and hints.
vtkSmartPointer<vtkTextActor> CornerText(const Rgb& background);

// Wires the keys of kViewKeys and point picking to `interactor` for the renderer of `scene`;
// `clouds` are the drawn clouds a pick can land on (read at each pick, so the live view can
// change them). `options` is changed by the keys (point size, EDL).
void InstallViewControls(vtkRenderWindowInteractor& interactor, vtkRenderer& renderer,
                         const std::function<const std::vector<DrawnCloud>&()>& clouds,
                         ColourMode colour, RenderOptions& options, vtkTextActor& text);

// "name  x y z  height -49.8 m" for drawn point `j` of `cloud`.
std::string PickText(const DrawnCloud& cloud, std::size_t j, ColourMode colour);

}  // namespace uwscan::viewer::internal
