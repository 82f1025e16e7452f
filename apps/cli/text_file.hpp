#pragma once

#include <string>

namespace uwscan::app {

// The whole file as text (scene YAML kept in dive logs). Throws uwscan::Error naming the path
// when it cannot be read.
std::string ReadText(const std::string& path);

}  // namespace uwscan::app
