// Surface photon merging (surf) as a batch pass: the camera pass records a surface query
// (kernels/shared/ub_surf.h) at each camera vertex on a non-delta surface, and this pass
// gathers the surface photons around each one through the hashed grid, on the host
// (estimateSurface, the twin) or as the OpenCL kernel kernels/surf.cl, with the same
// per-pair function. VCM without media merges inline in the camera pass
// (VertexCM::mergeVertices) with the same function.
#pragma once

#include <string>
#include <vector>

#include "core/vec.h"
#include "kernels/shared/ub_surf.h"
#include "render/light_vertex.h"

namespace ub {

class Bsdf;
class HashGrid;
class Scene;
struct Material;

/// The query of a camera vertex at pos with this BSDF (set up with dirFix towards the
/// camera side) and camera state; materialId selects the coating table of a rough plastic.
ub_surface_query makeSurfaceQuery(const Bsdf& bsdf, const Vec3& pos, int pathLength,
                                  const Rgb& throughput, uint32_t pixel, float dVCM, float dVM,
                                  float contProb, int materialId);

/// Every material's rough-plastic coating table, UB_ROUGH_PLASTIC_TABLE_SIZE floats per
/// material in Scene::materials order (zeros for other types): what the kernel reads at
/// ub_surface_query::bsdf.tableIndex.
std::vector<float> coatingTables(const Scene& scene);

/// The OpenCL build option that specialises ub_bsdf_eval_local (kernels/shared/ub_bsdf.h) to
/// the material types of these materials, "-DUB_BSDF_TYPES=0x...": every type a surface query
/// of the scene can carry (a blend's record, not evaluable, has the diffuse type).
std::string clBsdfTypesOption(const std::vector<Material>& materials);

struct SurfaceMergeInput {
    ub_mis_constants mis{};
    float radius = 0;
    float normalization = 0;  ///< 1 / (N_L pi r^2)
    int minLength = 0, maxLength = 1;
    const std::vector<LightVertex>* photons = nullptr;  ///< surface vertices
    const std::vector<ub_surface_query>* queries = nullptr;
    const std::vector<float>* tables = nullptr;  ///< coatingTables()
};

/// Host twin: (*out)[i] = throughput_i * normalization * sum over photons within r of
/// ub_surf_contribution; *pairs gets the number of photon-query pairs within r.
void estimateSurface(const SurfaceMergeInput& in, const HashGrid& grid, std::vector<Rgb>* out,
                     size_t* pairs);

}  // namespace ub
