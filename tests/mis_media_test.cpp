// The recursive MIS weights of vbpt (kernels/shared/ub_mis.h, MEDIA) on paths
// sampled through a real scene with media, against weights from explicit pdfs
// (tests/support/mis_path.h).
//
// Scene: box A [-1.2, 0]x[-1, 1]x[-1, 1] holds a homogeneous RGB medium (imaginary
// boundary), with a vacuum sphere nested in it (imaginary, higher priority); box B
// [0.2, 1.2]x[-1, 1]x[-1, 1] holds a NanoVDB grid medium whose voxels have random
// densities (some empty); a vacuum gap separates the boxes. A diffuse floor and back
// wall (real surfaces) and a quad light above, or a point light inside box A.
// Paths are sampled from the light as the engine samples them: Scene::traceMedia through
// the imaginary boundaries, free-flight sampling along the chain (sampleChainVertex, which
// also returns the distance pdfs of both directions that the engine feeds to the
// recursion), HG phase sampling at medium vertices, Lambert sampling at surfaces. Each
// segment therefore passes media, vacuum, nested boundaries and grid voxels.
//
// Two checks per path:
//  * the distance pdfs the engine feeds to the recursion (from free-flight sampling along
//    the chain, render/medium_walk.h) equal those recomputed independently by
//    Scene::shadowTransmittance between the two vertices -- the code path of connections,
//    NEE and light tracing, a different walk through the boundaries and the grid -- to
//    1e-3 relative (measured: 6e-4 at worst; float rounding of the two walks, whose segment
//    ends differ by the ray-origin offsets of ~1e-5 relative at boundary crossings, over
//    optical depths up to ~10);
//  * with those pdfs, the recursive weights (ub_mis.h as the engine runs it) equal the
//    explicit-pdf weights (bruteForceWeights) to 1e-4 (the tolerance of
//    tests/mis_bruteforce_test.cpp), and the weights of each path sum to 1.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "core/rng.h"
#include "kernels/shared/ub_phase.h"
#include "render/medium_walk.h"
#include "scene/bsdf.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "scene/shapes.h"
#include "scene/vdb_grid.h"
#include "tests/support/mis_path.h"

using namespace ub;
using namespace ub::test;

namespace {

TriangleMesh boxMesh(const Vec3& lo, const Vec3& hi) {
    TriangleMesh m = makeCube();  // [-1, 1]^3, outward normals
    m.normals.clear();
    transformMesh(m, Transform::translate((lo + hi) * 0.5f) * Transform::scale((hi - lo) * 0.5f));
    return m;
}

std::unique_ptr<Scene> mediaScene(bool pointLight) {
    auto scene = std::make_unique<Scene>();
    Material white;
    white.diffuse = Rgb(0.8f, 0.7f, 0.6f);
    int mat = scene->addMaterial(white);
    TriangleMesh floor = makeRectangle();
    transformMesh(floor, Transform::translate(Vec3(0, -1.3f, 0)) *
                             Transform::rotate(-90.0f, Vec3(1, 0, 0)) *
                             Transform::scale(Vec3(3.0f)));
    scene->addMesh(floor, mat, -1, "floor");
    TriangleMesh back = makeRectangle();
    transformMesh(back, Transform::translate(Vec3(0, 0, -1.5f)) * Transform::scale(Vec3(3.0f)));
    scene->addMesh(back, mat, -1, "back");
    Light light;
    if (pointLight) {
        light.type = LightType::Point;
        light.name = "point";
        light.position = Vec3(-0.6f, 0.3f, 0.2f);
        light.intensity = Rgb(2.0f);
    } else {
        TriangleMesh lamp = makeRectangle();
        transformMesh(lamp, Transform::translate(Vec3(0, 1.5f, 0)) *
                                Transform::rotate(90.0f, Vec3(1, 0, 0)) *
                                Transform::scale(Vec3(0.6f)));
        light.type = LightType::Area;
        light.name = "quad";
        light.radiance = Rgb(5.0f);
        for (uint32_t i : lamp.indices) light.triangles.push_back(lamp.positions[i]);
        int lightId = scene->addLight(light);
        scene->addMesh(lamp, mat, lightId, "lamp");
    }
    if (pointLight) scene->addLight(light);

    const int a = scene->addMedium(
        Medium::homogeneous(Rgb(0.1f, 0.2f, 0.05f), Rgb(0.9f, 0.5f, 0.3f), 0.4f), "fog");
    uint32_t boxA = scene->addMesh(boxMesh(Vec3(-1.2f, -1, -1), Vec3(0, 1, 1)), -1, -1, "box A");
    scene->setMediumBoundary(boxA, a, 0, /*imaginary=*/true);
    uint32_t bubble = scene->addSphere(Vec3(-0.5f, -0.4f, 0.1f), 0.35f, -1, -1, "bubble");
    scene->setMediumBoundary(bubble, -1, 1, /*imaginary=*/true);

    DenseFloatGrid dense(8, 16, 16, 0.0f);
    dense.voxelSize = 0.125f;
    dense.origin = Vec3(0.2f + 0.0625f, -1.0f + 0.0625f, -1.0f + 0.0625f);
    Rng rng(99, 1);
    for (float& v : dense.values) v = rng.uniform() < 0.15f ? 0.0f : 3.0f * rng.uniform();
    auto grid = VdbGrid::fromDense(dense, "density", "random grid");
    const int b =
        scene->addMedium(Medium::heterogeneous(grid, 1.0f, Rgb(0.9f, 0.8f, 0.95f), -0.3f), "smoke");
    uint32_t boxB = scene->addMesh(boxMesh(Vec3(0.2f, -1, -1), Vec3(1.2f, 1, 1)), -1, -1, "box B");
    scene->setMediumBoundary(boxB, b, 0, /*imaginary=*/true);
    scene->camera.setup(Vec3(0, 0, 4), Vec3(0, 0, 0), Vec3(0, 1, 0), 45.0f, 32, 32);
    scene->commit();
    return scene;
}

float roulette(const Scene& scene, int mediumId, const Vec3& p) {
    const MediumCoefficients c = mediumCoefficientsAt(scene.media[size_t(mediumId)], p);
    float q = 0.0f;
    for (int i = 0; i < 3; ++i)
        if (c.sigmaT[i] > 0.0f) q = std::max(q, c.sigmaS[i] / c.sigmaT[i]);
    return std::min(q, 1.0f);
}

struct SampledPath {
    MisPath sampled;  ///< distance pdfs from free-flight sampling (what the engine uses)
    MisPath walked;   ///< the same path, distance pdfs from Scene::shadowTransmittance
    int mediumVertices = 0, passedMediumSegments = 0;
};

/// One vertex of the sampled path: position, geometric normal (zero in a medium), stack
/// on the side the path continues to, medium flag.
struct Node {
    Vec3 pos, n;
    MediumStack stack;
    bool medium = false;
};

/// Samples a path of k segments through the scene; false if it escaped or died (retry).
bool samplePath(const Scene& scene, Rng& rng, int k, SampledPath* out) {
    const Light& light = scene.lights[0];
    MisPath p;
    p.lightKind = light.type == LightType::Point ? MisLightKind::Point : MisLightKind::Area;
    p.lightPickProb = 1.0f;
    Vec3 x0, dir;
    float emissionPdfW = 0, directPdfA = 0, cosLight = 0;
    Rgb le = light.emit(scene.sceneSphere, rng.uniform2(), rng.uniform2(), &x0, &dir, &emissionPdfW,
                        &directPdfA, &cosLight);
    if (isBlack(le) || cosLight < 0.1f) return false;
    if (p.lightKind == MisLightKind::Area) {
        p.emitPosPdf = directPdfA;
        p.emitDirPdfW = emissionPdfW / directPdfA;
    } else {
        p.emitPosPdf = 1;
        p.emitDirPdfW = emissionPdfW;
    }
    p.directPdfA = directPdfA;
    p.cosLight = cosLight;
    p.dist.assign(size_t(k + 1), 0.0f);
    p.v.assign(size_t(k), MisVertex{});
    p.distFwd.assign(size_t(k + 1), 1.0f);
    p.distRev.assign(size_t(k + 1), 1.0f);
    MisPath w = p;

    std::vector<Node> nodes(size_t(k + 1));
    nodes[0].pos = x0;
    nodes[0].n = p.lightKind == MisLightKind::Area ? Vec3(0, -1, 0) : Vec3(0.0f);
    nodes[0].stack = scene.mediumStackAt(x0 + dir * 1e-3f);
    Ray ray;
    ray.org = Scene::offsetRayOrigin(x0, nodes[0].n, dir);
    ray.dir = dir;
    MediumStack stack = nodes[0].stack;
    bool fromMedium = false;
    int mediumVertices = 0, passed = 0;
    for (int i = 1; i < k; ++i) {
        const MediumStack atStart = stack;
        MediumTrace trace;
        Hit hit;
        scene.traceMedia(ray, &stack, &trace, &hit);
        if (trace.overflow) return false;
        const ChainVertex cv = sampleChainVertex(scene, trace, ray.dir, fromMedium, rng);
        if (isBlack(cv.weight)) return false;
        for (int s = 0; s < (cv.scattered ? cv.segment : trace.count); ++s)
            passed += trace.segments[s].mediumId >= 0;
        MisVertex& v = p.v[size_t(i)];
        Node& node = nodes[size_t(i)];
        const Vec3 wFix = -ray.dir;
        Vec3 next;
        if (cv.scattered) {
            stack = atStart;
            scene.replayCrossings(trace, cv.segment, &stack);
            node.pos = cv.pos;
            node.n = Vec3(0.0f);
            node.medium = true;
            const Medium& m = scene.media[size_t(cv.mediumId)];
            float pdfW = 0;
            ub_float3 g = ub_hg_sample(ub_make_float3(wFix.x, wFix.y, wFix.z), m.g, rng.uniform(),
                                       rng.uniform(), &pdfW);
            next = normalize(Vec3(g.x, g.y, g.z));
            v.medium = true;
            v.cosIn = v.cosOut = 1.0f;
            v.pdfFwdW = v.pdfRevW = pdfW;
            v.cont = roulette(scene, cv.mediumId, cv.pos);
            ++mediumVertices;
            ray.org = cv.pos;
            ray.tMin = 0.0f;
        } else {
            if (!trace.hitSurface || hit.lightId >= 0) return false;
            node.pos = hit.pos;
            node.n = hit.geoNormal;
            Bsdf bsdf;
            if (!bsdf.setup(scene.materials[size_t(hit.materialId)], wFix, hit.geoNormal,
                            hit.shadingNormal, true))
                return false;
            float pdfW = 0, cosGen = 0;
            uint32_t event = 0;
            Rgb f = bsdf.sample(rng.uniform3(), &next, &pdfW, &cosGen, &event);
            if (isBlack(f) || cosGen < 0.1f || bsdf.cosThetaFix() < 0.1f) return false;
            v.cosIn = bsdf.cosThetaFix();
            v.cosOut = cosGen;
            v.pdfFwdW = pdfW;
            v.pdfRevW = bsdf.pdf(next, true);
            v.cont = std::min(1.0f, bsdf.continuationProb());
            ray = scene.spawnRay(hit, next);
        }
        if (!(v.cont > 0.0f)) return false;
        node.stack = stack;  // diffuse reflection stays on the same side
        p.dist[size_t(i)] = length(node.pos - nodes[size_t(i - 1)].pos);
        p.distFwd[size_t(i)] = cv.distPdfFwd;
        p.distRev[size_t(i)] = cv.distPdfRev;
        ray.dir = next;
        fromMedium = cv.scattered;
    }
    // Camera on the last direction, before the next real surface.
    const Node& last = nodes[size_t(k - 1)];
    {
        MediumStack s = stack;
        MediumTrace trace;
        Hit hit;
        scene.traceMedia(ray, &s, &trace, &hit);
        if (trace.overflow) return false;
        const float reach = std::min(trace.distance, 3.0f);
        if (!(reach > 0.2f)) return false;
        const float d = (0.1f + 0.8f * rng.uniform()) * reach;
        const Vec3 camPos = last.pos + ray.dir * d;
        Camera camera;
        const Vec3 up = std::fabs(ray.dir.y) < 0.9f ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
        camera.setup(camPos, last.pos, up, 40.0f, 64, 64);
        p.cameraPdfW = camera.pdfW(-ray.dir);
        p.dist[size_t(k)] = length(camPos - last.pos);
        const MediumShadow sh = scene.shadowTransmittance(
            camPos, Vec3(0.0f), scene.mediumStackAt(camPos), last.pos, last.n);
        if (sh.blocked) return false;
        // The camera subpath's first segment: the camera ray stopping at (or passing) x_{k-1}.
        p.distRev[size_t(k)] = distPdfToB(sh, last.medium);
        p.distFwd[size_t(k)] = sh.probPass;  // unused: no technique reaches the camera
    }
    // Reference distance pdfs: shadow walks between consecutive vertices.
    w = p;
    for (int i = 1; i < k; ++i) {
        const Node& a = nodes[size_t(i - 1)];
        const Node& b = nodes[size_t(i)];
        const MediumShadow sh = scene.shadowTransmittance(a.pos, a.n, a.stack, b.pos, b.n);
        if (sh.blocked) return false;  // numerically grazing: skip the path
        w.distFwd[size_t(i)] = distPdfToB(sh, b.medium);
        w.distRev[size_t(i)] = distPdfToA(sh, a.medium);
    }
    out->sampled = p;
    out->walked = w;
    out->mediumVertices = mediumVertices;
    out->passedMediumSegments = passed;
    return true;
}

}  // namespace

TEST(MisBruteForce, MediumScenePathsMatchExplicitPdfWeights) {
    int paths = 0, compared = 0, mediumVertices = 0, passedSegments = 0;
    double maxRel = 0;
    for (bool pointLight : {false, true}) {
        auto scene = mediaScene(pointLight);
        Rng rng(pointLight ? 77 : 78, 5);
        for (ub_uint h : {UB_MIS_POWER, UB_MIS_BALANCE}) {
            MisConfig cfg;
            cfg.useVM = false;
            cfg.heuristic = h;
            for (int n = 0; n < 300; ++n) {
                const int k = 2 + int(rng.uniform() * 6);
                SampledPath sp;
                bool ok = false;
                for (int tries = 0; tries < 500 && !ok; ++tries)
                    ok = samplePath(*scene, rng, k, &sp);
                ASSERT_TRUE(ok) << "could not sample a path of length " << k;
                ++paths;
                mediumVertices += sp.mediumVertices;
                passedSegments += sp.passedMediumSegments;
                for (int i = 1; i <= k; ++i) {
                    maxRel =
                        std::max(maxRel, std::fabs(sp.sampled.tFwd(i) / sp.walked.tFwd(i) - 1.0));
                    maxRel =
                        std::max(maxRel, std::fabs(sp.sampled.tRev(i) / sp.walked.tRev(i) - 1.0));
                    ASSERT_NEAR(sp.sampled.tFwd(i), sp.walked.tFwd(i), 1e-3f * sp.walked.tFwd(i))
                        << "forward distance pdf of segment " << i << " (k=" << k << ")";
                    ASSERT_NEAR(sp.sampled.tRev(i), sp.walked.tRev(i), 1e-3f * sp.walked.tRev(i))
                        << "reverse distance pdf of segment " << i << " (k=" << k << ")";
                }
                auto ref = bruteForceWeights(sp.sampled, cfg);
                auto rec = recursiveWeights(sp.sampled, cfg);
                ASSERT_EQ(ref.size(), rec.size());
                double sum = 0;
                for (size_t t = 0; t < ref.size(); ++t) {
                    ASSERT_NEAR(rec[t].weight, ref[t].weight, 1e-4)
                        << (pointLight ? "point" : "quad") << " k=" << k << " technique "
                        << ref[t].name();
                    sum += rec[t].weight;
                    ++compared;
                }
                if (!rec.empty()) ASSERT_NEAR(sum, 1.0, 1e-4);
            }
        }
    }
    std::printf(
        "[ mis      ] %d paths, %d weights, %d medium vertices, %d passed medium "
        "segments, distance pdfs agree to %.2g relative\n",
        paths, compared, mediumVertices, passedSegments, maxRel);
    EXPECT_EQ(paths, 1200);
    EXPECT_GT(mediumVertices, 500);
    EXPECT_GT(passedSegments, 300);
}
