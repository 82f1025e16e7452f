#include "apps/cli/json_output.hpp"

#include "scanner/common/atomic_file.hpp"

namespace uwscan::app {

void WriteJsonFile(const std::string& path, const nlohmann::json& value) {
  WriteFileAtomically(path, value.dump(2) + '\n');
}

}  // namespace uwscan::app
