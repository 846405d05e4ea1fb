// pb2d host twin: photon points x query beams, 2D kernel (the beam radiance
// estimate, Jarosz et al. 2008).
//
// Estimates, for each query beam, the radiance arriving at its origin from the
// photon points within r_pb2d of the beam (UPBP Table 1, "P-B2D"; per-pair value,
// MIS weight and normalisation 1 / (N_L pi r^2) in kernels/shared/ub_pb2d.h).
// Lookup: BVH over the photon points as boxes of their kernel sphere, traversed by
// the beam's segment (estimators/bvh.h). The medium along the query beam up to the
// photon's projection is evaluated exactly (regular tracking).

#include "estimators/beam_medium.h"
#include "estimators/bvh.h"
#include "estimators/volume_estimate.h"
#include "kernels/shared/ub_pb2d.h"
#include "scene/scene.h"

namespace ub {

void estimatePB2D(const VolumeEstimateInput& in, const Bvh& photonSpheres,
                  const std::vector<ub_photon_point>& photons,
                  const std::vector<ub_photon_key>& keys, std::vector<Rgb>* out, size_t* pairs) {
    const std::vector<ub_beam>& queries = *in.queryBeams;
    if (photons.empty() || queries.empty()) return;
    const float r = in.radius[UB_TECH_PB2D];
    const float normalization = ub_pb2d_normalization(in.lightPathCount, r);
    forEachQuery(queries.size(), 16, out, pairs, [&](size_t i, size_t* found) {
        const ub_beam& qb = queries[i];
        const float g = in.scene->media[qb.mediumId].g;
        const ub_float3 o = ub_f3_from(qb.origin), d = ub_f3_from(qb.dir);
        BeamMedium queryMedium;  // tabulated when the first pair is found
        queryMedium.reset(*in.scene, qb);
        Rgb sum(0.0f);
        photonSpheres.querySegment(
            Vec3(o.x, o.y, o.z), Vec3(d.x, d.y, d.z), qb.length, [&](uint32_t j) {
                float t = 0.0f;
                if (!ub_pb2d_near(keys[j], o, d, qb.length, qb.mediumId, r * r, &t)) return;
                const ub_photon_point& ph = photons[j];
                if (!ub_pb2d_length_ok(ph.pathLength, qb, ub_uint(in.minLength),
                                       ub_uint(in.maxLength)))
                    return;
                if (!queryMedium.built()) queryMedium.build();
                const ub_segment_eval s = queryMedium.eval(t);
                const ub_float3 c = ub_pb2d_contribution(in.mis, ph, qb, s, t, g, normalization);
                sum += Rgb(c.x, c.y, c.z);
                ++*found;
            });
        return sum;
    });
}

}  // namespace ub
