// Arbitrary output variables (see aov.h).
#include "render/aov.h"

#include <tbb/parallel_for.h>

#include "core/rng.h"
#include "scene/camera.h"

namespace ub {

std::vector<std::pair<std::string, Image>> renderAovs(const Scene& scene, int samples,
                                                      uint64_t seed) {
    const Camera& camera = scene.camera;
    const int w = camera.width(), h = camera.height();
    const auto& aovs = scene.settings.aovs;
    std::vector<std::pair<std::string, Image>> out;
    for (const auto& a : aovs) out.emplace_back(a.name, Image(w, h));
    if (aovs.empty() || samples <= 0) return out;
    tbb::parallel_for(0, h, [&](int y) {
        std::vector<Rgb> sum(aovs.size());
        for (int x = 0; x < w; ++x) {
            for (Rgb& s : sum) s = Rgb(0.0f);
            for (int s = 0; s < samples; ++s) {
                Rng rng = Rng::forPath(seed ^ 0xa0f5u, uint64_t(s),
                                       uint64_t(y) * uint64_t(w) + uint64_t(x));
                const Vec2 jitter = rng.uniform2(), lensU = rng.uniform2();
                float weight = 1.0f;
                const Vec2 raster =
                    scene.settings.pixelFilter.sampleRaster(x, y, jitter, w, h, &weight);
                if (weight <= 0.0f) continue;
                Hit hit;
                if (!scene.intersect(camera.generateRay(raster, lensU), &hit)) continue;
                for (size_t i = 0; i < aovs.size(); ++i) {
                    const std::string& t = aovs[i].type;
                    Rgb v(0.0f);
                    if (t == "depth")
                        v = Rgb(hit.dist);
                    else if (t == "position")
                        v = hit.pos;
                    else if (t == "uv")
                        v = Rgb(hit.uv.x, hit.uv.y, 0.0f);
                    else if (t == "geo_normal")
                        v = hit.geoNormal;
                    else if (t == "sh_normal")
                        v = hit.shadingNormal;
                    else if (t == "prim_index")
                        v = Rgb(float(hit.primId));
                    else if (t == "shape_index")
                        v = Rgb(float(hit.shapeId));
                    sum[i] += v * weight;
                }
            }
            for (size_t i = 0; i < aovs.size(); ++i)
                out[i].second.at(x, y) = sum[i] / float(samples);
        }
    });
    return out;
}

}  // namespace ub
