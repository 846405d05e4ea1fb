// Shadow rays through imaginary boundaries reach an area light that lies just beyond one
// (Scene::shadowTransmittance). Regression test: the walk used to keep its direction and
// remaining length after the origin offset at a crossing, which at grazing angles to the
// light's plane reached the light surface before the (offset) target and reported the
// segment blocked -- 19% of the NEE samples from the walls of cornell-fog, whose fog cube
// ends 0.01 below the light.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "core/rng.h"
#include "scene/io/json_loader.h"
#include "scene/scene.h"

using namespace ub;

TEST(NestedMedia, ShadowRaysReachAnAreaLightJustBeyondAnImaginaryBoundary) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    std::ifstream in(dir + "/cornell-fog.json");
    ASSERT_TRUE(in.good());
    nlohmann::json j = nlohmann::json::parse(in);
    nlohmann::json noFog = j;
    nlohmann::json shapes = nlohmann::json::array();
    for (nlohmann::json s : j["shapes"]) {
        if (s.value("name", "") == "fog volume") continue;
        s.erase("interior_medium");  // the glass sphere's vacuum interior
        s.erase("priority");
        shapes.push_back(s);
    }
    noFog["shapes"] = shapes;
    noFog.erase("media");
    auto fog = loadJsonSceneFromString(j.dump(), "cornell-fog.json", dir);
    auto plain = loadJsonSceneFromString(noFog.dump(), "cornell-fog.json", dir);
    ASSERT_TRUE(fog->hasMedia());
    ASSERT_FALSE(plain->hasMedia());
    const Light& light = fog->lights[0];

    // Wall points: the first real hit of rays from random points inside the box.
    Rng rng(9, 5);
    int samples = 0, visible = 0, mismatches = 0;
    for (int n = 0; n < 4000; ++n) {
        Ray r;
        r.org = Vec3(-1.1f + 2.2f * rng.uniform(), -1.1f + 2.2f * rng.uniform(),
                     -1.1f + 2.2f * rng.uniform());
        r.dir = sampleUniformSphere(rng.uniform2());
        MediumStack stack = fog->mediumStackAt(r.org);
        MediumTrace trace;
        Hit hit;
        fog->traceMedia(r, &stack, &trace, &hit);
        if (!trace.hitSurface || hit.materialId < 0) continue;
        fog->completeHit(trace.hitRay, &hit);
        Vec3 dirToLight;
        float dist = 0, pdfW = 0, emissionPdfW = 0, cosLight = 0;
        Rgb le = light.illuminate(fog->sceneSphere, hit.pos, rng.uniform2(), &dirToLight, &dist,
                                  &pdfW, &emissionPdfW, &cosLight);
        if (isBlack(le)) continue;
        const Vec3 lightPos = hit.pos + dirToLight * dist;
        MediumStack towards = stack;
        ASSERT_TRUE(fog->crossSurface(hit, -r.dir, dirToLight, &towards));
        const MediumShadow sh =
            fog->shadowTransmittance(hit.pos, hit.geoNormal, towards, lightPos, -dirToLight);
        const bool occluded = plain->occluded(hit.pos, hit.geoNormal, lightPos, -dirToLight);
        ++samples;
        visible += !occluded;
        mismatches += sh.blocked != occluded;
    }
    EXPECT_GT(samples, 2000);
    EXPECT_GT(visible, samples / 2);
    // Exact: the fog cube is imaginary, so it changes no visibility.
    EXPECT_EQ(mismatches, 0) << "of " << samples << " shadow rays";
}

// Where every surface a shadow ray can meet is real for its medium stack (no imaginary
// boundary; none of a lower priority), Scene::shadowTransmittance answers with one any-hit
// query instead of walking nearest hits. Its results equal the walk's, compared exactly:
// cornell-fog with a global fog instead of its imaginary cube (the glass sphere stays a
// priority-1 boundary), against the same scene plus a small imaginary sphere far outside
// the box, which makes every shadow ray walk.
TEST(NestedMedia, AnyHitShadowQueryEqualsTheWalk) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    std::ifstream in(dir + "/cornell-fog.json");
    ASSERT_TRUE(in.good());
    nlohmann::json j = nlohmann::json::parse(in);
    nlohmann::json shapes = nlohmann::json::array();
    for (const nlohmann::json& s : j["shapes"])
        if (s.value("name", "") != "fog volume") shapes.push_back(s);
    j["shapes"] = shapes;
    j["medium"] = "fog";
    nlohmann::json walked = j;
    walked["shapes"].push_back({{"name", "far bubble"},
                                {"type", "sphere"},
                                {"center", {40.0, 40.0, 40.0}},
                                {"radius", 0.5},
                                {"interior_medium", "fog"},
                                {"imaginary", true}});
    auto fast = loadJsonSceneFromString(j.dump(), "cornell-fog.json", dir);
    auto walk = loadJsonSceneFromString(walked.dump(), "cornell-fog.json", dir);
    const Light& light = fast->lights[0];
    Rng rng(17, 3);
    int blocked = 0, open = 0, differ = 0;
    auto same = [](const MediumShadow& a, const MediumShadow& b) {
        return a.blocked == b.blocked && a.transmittance.x == b.transmittance.x &&
               a.transmittance.y == b.transmittance.y && a.transmittance.z == b.transmittance.z &&
               a.probPass == b.probPass && a.pdfScatterFwdL == b.pdfScatterFwdL &&
               a.pdfScatterRevL == b.pdfScatterRevL;
    };
    for (int n = 0; n < 4000; ++n) {
        // From a random point in the box (in the fog or in the glass sphere's vacuum): to a
        // point of the light, and to another random point.
        const Vec3 a(-0.95f + 1.9f * rng.uniform(), -0.95f + 1.9f * rng.uniform(),
                     -0.95f + 1.9f * rng.uniform());
        const Vec3 b(-0.95f + 1.9f * rng.uniform(), -0.95f + 1.9f * rng.uniform(),
                     -0.95f + 1.9f * rng.uniform());
        const MediumStack stack = fast->mediumStackAt(a);
        Vec3 dirToLight;
        float dist = 0, pdfW = 0, emissionPdfW = 0, cosLight = 0;
        light.illuminate(fast->sceneSphere, a, rng.uniform2(), &dirToLight, &dist, &pdfW,
                         &emissionPdfW, &cosLight);
        const Vec3 targets[2] = {a + dirToLight * dist, b};
        for (int t = 0; t < 2; ++t) {
            const Vec3 n = t == 0 ? -dirToLight : Vec3(0.0f);
            const MediumShadow f = fast->shadowTransmittance(a, Vec3(0.0f), stack, targets[t], n);
            const MediumShadow w = walk->shadowTransmittance(a, Vec3(0.0f), stack, targets[t], n);
            differ += !same(f, w);
            (f.blocked ? blocked : open) += 1;
        }
    }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(blocked, 400);  // the spheres and the light box block some
    EXPECT_GT(open, 4000);
}

// Where some boundary is imaginary (or of a lower priority than another), a shadow ray is
// answered by one any-hit traversal that records the crossings (Scene::shadowCrossings)
// instead of a nearest-hit query per leg. cornell-fog as shipped (its fog cube is imaginary)
// takes that path for every ray; the same scene plus a small imaginary sphere far outside the
// box walks every ray hit by hit (a sphere's intersector calls no Embree filter). Blocked or
// not agrees exactly; the transmittance, pass probability and stopping densities agree within
// 1e-5 relative (below 1e-6 for these rays): the walk restarts each leg from an origin moved
// off the surface by Scene::rayOffsetLength (1e-5 scaled) and re-aimed at the end point, so
// its segment lengths differ from the single ray's by about that offset, and sigma_t = 0.27 in
// this fog.
TEST(NestedMedia, OneTraversalShadowQueryAgreesWithTheWalk) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    std::ifstream in(dir + "/cornell-fog.json");
    ASSERT_TRUE(in.good());
    nlohmann::json j = nlohmann::json::parse(in);
    nlohmann::json walked = j;
    walked["shapes"].push_back({{"name", "far bubble"},
                                {"type", "sphere"},
                                {"center", {40.0, 40.0, 40.0}},
                                {"radius", 0.5},
                                {"interior_medium", "fog"},
                                {"imaginary", true}});
    auto fast = loadJsonSceneFromString(j.dump(), "cornell-fog.json", dir);
    auto walk = loadJsonSceneFromString(walked.dump(), "cornell-fog.json", dir);
    const Light& light = fast->lights[0];
    Rng rng(23, 5);
    int blocked = 0, open = 0, crossed = 0, differ = 0;
    auto close = [](float a, float b) { return std::abs(a - b) <= 1e-5f * std::abs(b) + 1e-30f; };
    for (int n = 0; n < 4000; ++n) {
        // From a random point in or around the box (fog, the glass sphere's vacuum, outside
        // the fog cube): to a point of the light, and to another random point.
        const Vec3 a(-1.1f + 2.2f * rng.uniform(), -1.1f + 2.2f * rng.uniform(),
                     -1.1f + 2.2f * rng.uniform());
        const Vec3 b(-1.1f + 2.2f * rng.uniform(), -1.1f + 2.2f * rng.uniform(),
                     -1.1f + 2.2f * rng.uniform());
        const MediumStack stack = fast->mediumStackAt(a);
        Vec3 dirToLight;
        float dist = 0, pdfW = 0, emissionPdfW = 0, cosLight = 0;
        light.illuminate(fast->sceneSphere, a, rng.uniform2(), &dirToLight, &dist, &pdfW,
                         &emissionPdfW, &cosLight);
        const Vec3 targets[2] = {a + dirToLight * dist, b};
        for (int t = 0; t < 2; ++t) {
            const Vec3 n = t == 0 ? -dirToLight : Vec3(0.0f);
            Scene::ShadowCrossing crossings[MediumTrace::kMaxSegments];
            int count = 0;
            const Vec3 d = targets[t] - a;
            ASSERT_NE(fast->shadowCrossings(a, d / length(d), length(d), crossings,
                                            MediumTrace::kMaxSegments, &count),
                      Scene::ShadowQuery::kUnavailable);
            const MediumShadow f = fast->shadowTransmittance(a, Vec3(0.0f), stack, targets[t], n);
            const MediumShadow w = walk->shadowTransmittance(a, Vec3(0.0f), stack, targets[t], n);
            const bool same =
                f.blocked == w.blocked && close(f.transmittance.x, w.transmittance.x) &&
                close(f.transmittance.y, w.transmittance.y) &&
                close(f.transmittance.z, w.transmittance.z) && close(f.probPass, w.probPass) &&
                close(f.pdfScatterFwdL, w.pdfScatterFwdL) &&
                close(f.pdfScatterRevL, w.pdfScatterRevL);
            differ += !same;
            (f.blocked ? blocked : open) += 1;
            crossed += !f.blocked && f.segmentCount > 1;
        }
    }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(blocked, 400);
    EXPECT_GT(open, 4000);
    EXPECT_GT(crossed, 1000);  // rays that cross the fog cube
}
