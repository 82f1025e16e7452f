#include "viewer/render/display.hpp"

#include <X11/Xlib.h>

#include <cstdlib>
#include <mutex>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::viewer {
namespace {

constexpr const char* kHowTo =
    "run under xvfb-run -a -s \"-screen 0 1280x1024x24\" (packages xvfb, xauth)";

}  // namespace

void RequireDisplay() {
  // The first connection that answers is kept open until the process exits: an X server such as
  // Xvfb resets when its last client leaves, and a window VTK opens during that reset finds no
  // server and aborts the process. With this client always there, it never resets under us.
  static std::mutex mutex;
  static Display* kept = nullptr;
  const std::lock_guard<std::mutex> lock(mutex);
  if (kept != nullptr) return;
  const char* name = std::getenv("DISPLAY");
  if (name == nullptr || *name == '\0') {
    throw Error(std::string("no X display: $DISPLAY is not set; VTK renders only through X "
                            "here, even offscreen; ") +
                kHowTo);
  }
  Display* display = XOpenDisplay(name);
  if (display == nullptr) {
    throw Error(std::string("no X display: cannot open '") + name + "'; " + kHowTo);
  }
  int opcode = 0, event = 0, error = 0;
  const bool glx = XQueryExtension(display, "GLX", &opcode, &event, &error);
  if (!glx) {
    XCloseDisplay(display);
    throw Error(std::string("X display '") + name + "' has no GLX extension, which VTK's OpenGL " +
                "rendering needs; " + kHowTo);
  }
  kept = display;
}

}  // namespace uwscan::viewer
