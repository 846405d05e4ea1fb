// Triangle mesh files: OBJ (tinyobjloader) and PLY (scene/ply_reader.h). Meshes are
// validated: non-finite positions, out-of-range indices and meshes without
// any non-degenerate triangle are errors; degenerate (zero-area) triangles are
// dropped with a warning that says how many.
#pragma once

#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace ub {

/// Loads an .obj or .ply file (chosen by extension, case-insensitive) into object space.
/// On failure adds diagnostics (file = path, where = `where`, e.g. the JSON path of the
/// shape) and returns an empty mesh. Never throws for bad file contents.
TriangleMesh loadMeshFile(const std::string& path, Diagnostics& diags, const std::string& where);

}  // namespace ub
