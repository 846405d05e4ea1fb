// Internal to the lights (light.cpp, light_projected.cpp): the projected-texture parts of
// Mitsuba 3's `spot` (a `texture`) and `projector`; the conventions are in
// light_projected.cpp's banner.
#pragma once

#include "scene/light.h"

namespace ub {

/// Spot with a texture, projector: checks the fields, normalises the frame (built from
/// `direction` when frameX and frameY are zero), sets projTan and the projector's sampling
/// distribution. Throws InputError naming the light.
void prepareProjected(Light& l);

/// Projector: a direction (world, unit, leaving the light) drawn with the solid-angle
/// density that projectedIntensity() reports.
Vec3 sampleProjectorDirection(const Light& l, const Vec2& rnd);

}  // namespace ub
