#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

namespace uwscan::app {

// Writes JSON to `path` atomically (a temporary file renamed over the target), so an earlier
// file stays readable if anything fails. Throws uwscan::Error naming the path.
void WriteJsonFile(const std::string& path, const nlohmann::json& value);

// A 4 x 4 matrix (a pose) as four rows of four numbers.
nlohmann::json MatrixJson(const Eigen::Matrix4d& m);

}  // namespace uwscan::app
