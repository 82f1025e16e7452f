#include "scanner/common/temporary_folder.hpp"

#include <cstdlib>
#include <string>
#include <system_error>

#include "scanner/common/error.hpp"

namespace uwscan {

std::filesystem::path TemporaryFolder() {
  std::error_code error;
  const std::filesystem::path folder = std::filesystem::temp_directory_path(error);
  if (!error) return folder;
  const char* tmpdir = std::getenv("TMPDIR");
  const std::string which =
      tmpdir != nullptr ? "$TMPDIR (" + std::string(tmpdir) + ")" : "the temporary folder";
  throw Error(which + " is not a folder (" + error.message() +
              "): set TMPDIR to a writable folder with room for uwscan's temporary files");
}

}  // namespace uwscan
