#pragma once

namespace uwscan::viewer {

// VTK 9.1 on Debian 12 renders only through X (no EGL or OSMesa build): without a display even
// an offscreen render aborts the whole process. Every entry point of this module that renders
// calls RequireDisplay() before its first VTK render call.
//
// Throws uwscan::Error, with a one-line reason and what to do, when $DISPLAY is unset or empty,
// when the X server it names does not answer, or when that server has no GLX extension (VTK's
// OpenGL window needs it). Cheap: one connection opened and closed.
void RequireDisplay();

}  // namespace uwscan::viewer
