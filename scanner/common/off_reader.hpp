#pragma once

#include <filesystem>

#include "scanner/common/triangle_mesh.hpp"

namespace uwscan::scanner {

// Reads an OFF mesh: "OFF" (or COFF / NOFF / CNOFF, whose extra vertex columns are ignored),
// then "vertices faces edges", the vertices (x y z first on each line) and the faces
// ("n i1 .. in", extra columns such as colours ignored; polygons fan-triangulated). Comments
// (#) and blank lines may come anywhere. uwscan's own bounded reader: Assimp 5.2's OFF importer
// crashes on cut files (`uwscan bench robustness`). Throws uwscan::Error naming the file and
// line when it is not OFF, a count is impossible for the file's size, a line is cut short, or
// an index is out of range.
TriangleMesh ReadOff(const std::filesystem::path& path);

}  // namespace uwscan::scanner
