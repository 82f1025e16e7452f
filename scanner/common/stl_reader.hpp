#pragma once

#include <filesystem>

#include "scanner/common/triangle_mesh.hpp"

namespace uwscan::scanner {

// Reads an STL mesh, binary (an 80-byte header, a little-endian uint32 triangle count, then 50
// bytes per triangle: normal, three vertices as float32, a uint16 attribute) or ASCII ("solid",
// then "facet normal ... outer loop, vertex x y z ..., endloop endfacet", "endsolid"; a loop of
// more than three vertices is fan-triangulated; several solids make one mesh). A file whose
// size is exactly that of its binary count is binary even when its header starts with "solid",
// as many exporters write. Vertices identical to the bit are merged (STL repeats them per
// triangle) and triangles left with a repeated vertex are dropped (zero-area triangles with
// three distinct corners are kept). uwscan's own bounded reader: Assimp 5.2's STL importer
// leaks memory on damaged files (tests/fuzz/regressions/mesh_stl). Throws uwscan::Error naming
// the file (and the line, for ASCII) when it is neither kind of STL, is cut short, or a loop
// has fewer than three vertices.
TriangleMesh ReadStl(const std::filesystem::path& path);

}  // namespace uwscan::scanner
