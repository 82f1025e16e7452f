#pragma once

#include <filesystem>
#include <string>

namespace uwscan::app {

// The folder of uwscan's shipped data (scanners/, scenes/, genicam/, rviz/), found wherever the
// program runs from: $UWSCAN_DATA_DIR when set; else share/uwscan of the prefix the program is
// installed in (PREFIX/bin/uwscan reads PREFIX/share/uwscan); else the data/ folder of the source
// tree it was built from. Throws uwscan::Error naming the places tried when none is a folder.
// Default data paths go through it; paths a user gives stay relative to the working folder.
std::filesystem::path DataFolder();

// A --data option's value when one was given (relative to the working folder), else DataFolder().
std::filesystem::path DataFolderOr(const std::string& given);

}  // namespace uwscan::app
