#include "viewer/render/interactive_view.hpp"

#include "scanner/common/error.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/view_interaction.hpp"

namespace uwscan::viewer {

void ShowScene(const Scene& scene, const RenderOptions& options_in, const std::string& title) {
  options_in.Check();
  if (scene.empty()) throw Error(title + ": nothing to show");
  RequireDisplay();
  RenderOptions options = options_in;
  internal::VtkScene vtk = internal::BuildVtkScene(scene, options);
  vtkSmartPointer<vtkRenderWindow> window =
      internal::MakeRenderWindow(options, /*offscreen=*/false);
  window->SetWindowName(title.c_str());
  window->AddRenderer(vtk.renderer);
  vtkSmartPointer<vtkTextActor> text = internal::CornerText(options.background);
  text->SetInput(kViewKeys);
  vtk.renderer->AddViewProp(text);
  internal::ApplyCameraPreset(*vtk.renderer, options.camera, options.up, vtk.fit_bounds);

  vtkNew<vtkRenderWindowInteractor> interactor;
  interactor->SetRenderWindow(window);
  internal::InstallViewControls(
      *interactor, *vtk.renderer,
      [&vtk]() -> const std::vector<internal::DrawnCloud>& { return vtk.clouds; }, options.colour,
      options, *text);
  window->Render();
  interactor->Start();
}

}  // namespace uwscan::viewer
