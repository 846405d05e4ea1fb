// Mitsuba's `.serialized` triangle meshes, format versions 3 and 4 (the ones Mitsuba 0.5-3
// write for scenes in the wild; described in Mitsuba 3's documentation of its `serialized`
// shape plugin). Little endian:
//   uint16 0x041C, uint16 version (3 or 4), then a zlib stream holding
//     uint32 flags (0x1 vertex normals, 0x2 texture coordinates, 0x8 vertex colours,
//                   0x10 face normals, 0x1000 float32, 0x2000 float64),
//     version 4: the shape's name, NUL-terminated,
//     uint64 vertex count V, uint64 triangle count F,
//     V x 3 positions, [V x 3 normals], [V x 2 uvs], [V x 3 colours] (float32 or float64),
//     F x 3 uint32 vertex indices;
//   several shapes are concatenated (each with its own header and zlib stream), and the file
//   ends with a dictionary: the file offset of every shape (uint32 in version 3, uint64 in
//   version 4) followed by the uint32 shape count.
// Every count, offset and index is checked against the file and the decompressed data:
// a truncated or corrupt file is an error naming the file and what is wrong, never a crash
// or an allocation the file cannot back.
#pragma once

#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace ub {

/// Reads shape `shapeIndex` (>= 0) of the .serialized file at `path` (object space; vertex
/// colours are read and dropped). Face normals (the file's flag or faceNormals) drop the
/// vertex normals. Zero-area triangles are dropped with a warning. On failure adds
/// diagnostics (file = path, where = `where`) and returns an empty mesh.
TriangleMesh loadSerializedMesh(const std::string& path, int shapeIndex, bool faceNormals,
                                Diagnostics& diags, const std::string& where);

}  // namespace ub
