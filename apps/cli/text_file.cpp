#include "apps/cli/text_file.hpp"

#include <fstream>
#include <sstream>

#include "scanner/common/error.hpp"

namespace uwscan::app {

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace uwscan::app
