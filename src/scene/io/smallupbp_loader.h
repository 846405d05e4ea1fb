// SmallUPBP scenes (Krivanek et al. 2014, "Unifying Points, Beams, and Paths in
// Volumetric Light Transport Simulation"; the scenes of its paper and of
// gpuupbp): X.obj (geometry), the .mtl it names (materials) and X.obj.aux
// (camera, media, material extras, lights). docs/smallupbp.md describes how
// every keyword maps to unibeam and what is not representable.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace ub {

/// Loads and commits the SmallUPBP scene `objPath` (its .obj.aux is objPath + ".aux").
/// Throws InputError listing every problem (file:line:column); warnings (spellings that
/// SmallUPBP accepts, features unibeam approximates) go to *warnings when given.
std::unique_ptr<Scene> loadSmallUpbpScene(const std::string& objPath,
                                          std::vector<Diagnostic>* warnings = nullptr);

/// World -> environment-map-frame rotation that makes unibeam's lat-long lookup
/// (scene/light.h) read a SmallUPBP environment map (z up, u = 1/2 - atan2(y, x) / 2pi,
/// v = acos(z) / pi, the map turned by `rotatePixels` of its `width` columns) the way
/// SmallUPBP does.
Transform smallUpbpEnvToWorld(int rotatePixels, int width);

}  // namespace ub
