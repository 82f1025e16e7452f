#pragma once

#include <filesystem>
#include <memory>

#include "scanner/lasers/galvo_laser.hpp"
#include "scanner/triangulation/light_surface_table.hpp"

namespace uwscan::scanner {

// The light surface table of a laser, kept on disk so that it is fitted once per calibration,
// not once per run: the cone fits take about a second (201 mirror steps) while reading the
// table back takes a millisecond. A file holds the exact inputs it was computed from (every
// laser parameter and option, as bits) and a checksum; it is used only when both match, so a
// changed calibration, a changed option or a damaged file makes a new table, never a wrong one.
// Files are written through a temporary file and a rename (processes may share the folder).
struct CachedTable {
  std::shared_ptr<const LightSurfaceTable> table;
  bool from_cache = false;
};

// The table of (laser, options), read from `folder` when a file of the same inputs is there,
// else computed and stored there (the folder is created). A folder that cannot be written only
// costs the saving: the computed table is returned all the same.
CachedTable LoadOrBuildLightSurfaceTable(const GalvoLaser& laser,
                                         const LightSurfaceTableOptions& options,
                                         const std::filesystem::path& folder);

}  // namespace uwscan::scanner
