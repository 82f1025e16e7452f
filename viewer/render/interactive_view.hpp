#pragma once

#include <string>

#include "viewer/scene/render_options.hpp"
#include "viewer/scene/scene.hpp"

namespace uwscan::viewer {

// The keys of an interactive view, for help texts.
inline constexpr const char* kViewKeys =
    "mouse: rotate / pan (shift) / zoom (wheel); p: pick the point under the mouse; "
    "f: fit, t: top, s: side; + / -: point size; e: Eye-Dome Lighting on/off; q: quit";

// Opens a window on `scene` and returns when it is closed. Picking a point (key p) shows its
// file, world coordinates and the value it is coloured by in the window's corner. Throws
// uwscan::Error when there is no X display (checked before any window opens), the scene is
// empty or an option is invalid.
void ShowScene(const Scene& scene, const RenderOptions& options, const std::string& title);

}  // namespace uwscan::viewer
