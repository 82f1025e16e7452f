#include "apps/json_output.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "scanner/common/error.hpp"

namespace uwscan::app {

void WriteJsonFile(const std::string& path, const nlohmann::json& value) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary);
    if (!out) throw Error(path + ": cannot write (does the folder exist?)");
    out << value.dump(2) << '\n';
    if (!out.flush()) throw Error(path + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::remove(temporary.c_str());
    throw Error(path + ": cannot replace: " + ec.message());
  }
}

}  // namespace uwscan::app
