// PLY meshes (ASCII, binary little and big endian): positions x y z, optional normals
// nx ny nz and uvs (u v, s t, texture_u texture_v or texture_s texture_t), faces from the
// 'face' element's vertex_indices (or vertex_index) list, polygons as fans; every other
// element and property is read and skipped. See ply_reader.cpp for why unibeam reads PLY
// itself.
#pragma once

#include <functional>
#include <string>

#include "scene/scene.h"

namespace ub {

/// Where readPly reports: error(message, line, column) with the file's line (ASCII body and
/// header; 0: none) and warning(message, line).
struct PlyReport {
    std::function<void(const std::string&, int, int)> error;
    std::function<void(const std::string&, int)> warning;
};

/// Reads the PLY file at path into *out. False after at least one error.
bool readPly(const std::string& path, const PlyReport& report, TriangleMesh* out);

}  // namespace ub
