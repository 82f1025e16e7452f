#include "apps/cli/json_output.hpp"

#include "scanner/common/atomic_file.hpp"

namespace uwscan::app {

void WriteJsonFile(const std::string& path, const nlohmann::json& value) {
  WriteFileAtomically(path, value.dump(2) + '\n');
}

nlohmann::json MatrixJson(const Eigen::Matrix4d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

}  // namespace uwscan::app
