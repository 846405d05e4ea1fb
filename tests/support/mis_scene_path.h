// Random full paths through scenes built in code, with the real Bsdf and Light
// implementations supplying every pdf, converted to the MisPath description of
// tests/support/mis_path.h. The path is sampled from the light: x_0 by
// Light::emit, each x_i (1 <= i < k) placed at a random distance along the
// sampled direction on a randomly tilted surface of a random material (so
// vertices are diffuse, glossy, rough or specular), its next direction sampled
// by Bsdf::sample, and the pinhole camera placed along the last direction,
// looking at x_{k-1}. Visibility does not enter MIS weights, so no BVH is needed.
//
// Along the way it checks what the recursive weights take for granted: the
// camera-side BSDF at x_i (dirFix towards x_{i+1}) samples x_{i-1} with the
// light-side BSDF's reverse pdf and vice versa, and both roles use the same
// Russian-roulette probability. Mismatches are reported in *problem.
#pragma once

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "core/rng.h"
#include "render/vcm.h"
#include "scene/bsdf.h"
#include "scene/camera.h"
#include "scene/light.h"
#include "tests/support/mis_path.h"

namespace ub::test {

inline Vec3 randomUnitVector(Rng& rng) {
    return sampleUniformSphere(rng.uniform2());
}

inline bool relClose(float a, float b, float rel) {
    return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)) + 1e-12f;
}

/// Samples a path with k segments. Returns false (and leaves *problem empty) when sampling
/// failed (absorbed, grazing); callers retry. *problem is set when a BSDF role mismatch
/// was found.
inline bool sampleScenePath(Rng& rng, const Light& light, MisLightKind kind, float lightPickProb,
                            const SceneSphere& sphere, const std::vector<Material>& materials,
                            int k, MisPath* out, std::string* problem) {
    MisPath p;
    p.lightKind = kind;
    p.lightPickProb = lightPickProb;
    Vec3 x0, dir;
    float emissionPdfW = 0, directPdfA = 0, cosLight = 0;
    Rgb le = light.emit(sphere, rng.uniform2(), rng.uniform2(), &x0, &dir, &emissionPdfW,
                        &directPdfA, &cosLight);
    if (isBlack(le) || !(emissionPdfW > 0) || cosLight < 0.1f) return false;
    if (kind == MisLightKind::Area) {
        p.emitPosPdf = directPdfA;  // one-sided area light: uniform by area
        p.emitDirPdfW = emissionPdfW / directPdfA;
    } else {
        p.emitPosPdf = 1;
        p.emitDirPdfW = emissionPdfW;
    }
    p.directPdfA = directPdfA;
    p.cosLight = cosLight;
    p.dist.assign(k + 1, 0);
    p.v.assign(k, MisVertex{});

    Vec3 prev = x0;
    for (int i = 1; i < k; ++i) {
        float dist = 0.3f + 1.7f * rng.uniform();
        Vec3 x = prev + dir * dist;
        // A normal facing the incoming ray with |cos| >= 0.15 (dielectrics: either side).
        Vec3 n;
        do {
            n = randomUnitVector(rng);
        } while (dot(n, -dir) < 0.15f);
        const Material& mat = materials[rng.nextU32() % materials.size()];
        bool isDielectric =
            mat.type == MaterialType::Dielectric || mat.type == MaterialType::RoughDielectric;
        if (isDielectric && rng.uniform() < 0.5f) n = -n;
        Bsdf lightBsdf;
        if (!lightBsdf.setup(mat, -dir, n, n, /*fromLight=*/true)) return false;
        Vec3 next;
        float pdfW = 0, cosGen = 0;
        uint32_t event = 0;
        Rgb f = lightBsdf.sample(rng.uniform3(), &next, &pdfW, &cosGen, &event);
        if (isBlack(f) || !(pdfW > 0) || cosGen < 0.1f) return false;
        MisVertex& v = p.v[i];
        v.cosIn = lightBsdf.cosThetaFix();
        v.cosOut = cosGen;
        v.specular = (event & kEventSpecular) != 0;
        v.pdfFwdW = pdfW;
        v.pdfRevW = v.specular ? pdfW : lightBsdf.pdf(next, /*reverse=*/true);
        v.cont = vcmContinuationProb(lightBsdf);
        if (!(v.cont > 0) || !(v.pdfRevW > 0)) return false;

        // The same point seen by a camera subpath arriving from x_{i+1}.
        Bsdf cameraBsdf;
        if (!cameraBsdf.setup(mat, next, n, n, /*fromLight=*/false)) return false;
        std::ostringstream why;
        if (!relClose(vcmContinuationProb(cameraBsdf), v.cont, 1e-6f))
            why << "continuation probability differs between light and camera roles (" << v.cont
                << " vs " << vcmContinuationProb(cameraBsdf) << ")";
        if (!v.specular) {
            float camDir = 0, camRev = 0;
            cameraBsdf.evaluate(-dir, nullptr, &camDir, &camRev);
            if (!relClose(camDir, v.pdfRevW, 1e-3f) || !relClose(camRev, v.pdfFwdW, 1e-3f))
                why << "camera-side pdfs (" << camDir << ", " << camRev
                    << ") differ from light-side reverse/direct pdfs (" << v.pdfRevW << ", "
                    << v.pdfFwdW << ")";
        }
        if (!why.str().empty()) {
            *problem =
                "material '" + mat.name + "' at vertex " + std::to_string(i) + ": " + why.str();
            return false;
        }
        p.dist[i] = dist;
        prev = x;
        dir = next;
    }
    // Pinhole camera on the last sampled direction, looking back at x_{k-1}.
    float lastDist = 0.5f + 2.0f * rng.uniform();
    Vec3 camPos = prev + dir * lastDist;
    Vec3 offset = randomUnitVector(rng) * (0.1f * lastDist);
    Vec3 up = std::fabs(dir.z) < 0.9f ? Vec3(0, 0, 1) : Vec3(1, 0, 0);
    Camera camera;
    camera.setup(camPos, prev + offset, up, 40.0f, 64, 64);
    p.dist[k] = lastDist;
    p.cameraPdfW = camera.pdfW(-dir);
    if (!(p.cameraPdfW > 0)) return false;
    *out = p;
    return true;
}

}  // namespace ub::test
