// Arbitrary output variables (Mitsuba 3's `aov` integrator): per pixel, the mean over camera
// samples (drawn from the scene's pixel filter, as the image's are) of a quantity at the first
// surface the camera ray hits, 0 where it hits none. Types, as Mitsuba names them: depth (the
// distance along the ray), position, uv, geo_normal, sh_normal (unit, world space),
// prim_index, shape_index (unibeam's shape order: a mesh is one shape, and an instance adds one
// per member). Media do not stop the rays (as Mitsuba's aov). One-channel types fill the
// layer's three channels with the same value.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "scene/aov_types.h"
#include "scene/scene.h"

namespace ub {

/// One layer per scene.settings.aovs entry, named by it, `samples` camera samples per pixel
/// (seeded by `seed`).
std::vector<std::pair<std::string, Image>> renderAovs(const Scene& scene, int samples,
                                                      uint64_t seed);

}  // namespace ub
