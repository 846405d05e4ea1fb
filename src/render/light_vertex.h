// LightVertex: the host's view of the shared light-vertex record
// (kernels/shared/ub_light_vertex.h, where the fields and their meaning are
// documented). It adds no data, only Vec3 accessors, so an array of
// LightVertex is an array of ub_light_vertex and can be uploaded as it is.
#pragma once

#include <type_traits>

#include "core/vec.h"
#include "kernels/shared/ub_light_vertex.h"

namespace ub {

/// Vec3 from a record's float[3] field, and back.
inline Vec3 loadF3(const float v[3]) {
    return Vec3(v[0], v[1], v[2]);
}
inline void storeF3(float v[3], const Vec3& a) {
    v[0] = a.x;
    v[1] = a.y;
    v[2] = a.z;
}

struct LightVertex : ub_light_vertex {
    Vec3 pos3() const { return loadF3(position); }
    Vec3 throughput3() const { return loadF3(throughput); }
    Vec3 dirFix3() const { return loadF3(dirFix); }
    Vec3 geoNormal3() const { return loadF3(geoNormal); }
    Vec3 shadingNormal3() const { return loadF3(shadingNormal); }
    Vec2 uv2() const { return Vec2(uv[0], uv[1]); }
    Rgb attribute3() const { return loadF3(attribute); }
    Vec3 tangent3() const { return loadF3(tangent); }
    bool inMedium() const { return (flags & UB_LIGHT_VERTEX_IN_MEDIUM) != 0; }
    /// Medium of a medium vertex (index into Scene::media).
    int mediumId() const { return int(materialId); }
};

static_assert(std::is_standard_layout<LightVertex>::value, "LightVertex must be flat");
static_assert(std::is_trivially_copyable<LightVertex>::value, "LightVertex must be flat");
static_assert(sizeof(LightVertex) == sizeof(ub_light_vertex), "LightVertex adds no data");
static_assert(sizeof(Vec3) == 12,
              "Vec3 must be three packed floats (the grids read float[3] as Vec3)");

}  // namespace ub
