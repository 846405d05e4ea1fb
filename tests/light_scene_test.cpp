// Lights seen through the real Scene: the hit that Scene::intersect reports for a
// sampled light point (its position and geometric normal) must give, through
// Light::radianceAlong, the radiance and pdfs that illuminate() and emit() used.
// This pins down the normal convention shared by scene.cpp and light.cpp (front side
// = normalize((p1-p0) x (p2-p0)) for triangles, outward for spheres).
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "scene/io/mitsuba_loader.h"
#include "scene/light.h"
#include "scene/scene.h"

namespace ub {
namespace {

bool relNear(double a, double b, double rel) {
    return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b));
}

struct LitScene {
    Scene scene;
    int quadLight = -1, ballLight = -1;
};

/// A two-sided tilted quad and a one-sided sphere, each an area light of its own.
void buildScene(LitScene* s) {
    TriangleMesh quad;
    quad.positions = {Vec3(-1, -1, 2), Vec3(1, -1, 2.5f), Vec3(1, 1, 2.5f), Vec3(-1, 1, 2)};
    quad.indices = {0, 1, 2, 0, 2, 3};
    Light ql;
    ql.type = LightType::Area;
    ql.name = "quad";
    ql.radiance = Rgb(2.0f);
    ql.twoSided = true;
    for (uint32_t i : quad.indices) ql.triangles.push_back(quad.positions[i]);
    s->quadLight = s->scene.addLight(ql);
    s->scene.addMesh(quad, -1, s->quadLight, "quad");

    Light bl;
    bl.type = LightType::Area;
    bl.name = "ball";
    bl.radiance = Rgb(3.0f);
    bl.isSphere = true;
    bl.position = Vec3(0, 0, -3);
    bl.sphereRadius = 0.75f;
    s->ballLight = s->scene.addLight(bl);
    s->scene.addSphere(bl.position, bl.sphereRadius, -1, s->ballLight, "ball");
    s->scene.commit();
}

TEST(Light, SceneHitsReproduceIlluminatePdfs) {
    LitScene s;
    buildScene(&s);
    Rng rng(21, 1);
    int checked = 0, misses = 0;
    for (int i = 0; i < 4000; ++i) {
        int id = (i % 2) ? s.quadLight : s.ballLight;
        const Light& l = s.scene.lights[id];
        Vec3 x = Vec3(-0.5f) + rng.uniform3();  // between the two lights
        Vec3 dir;
        float dist, directPdfW, emPdfW, cosL;
        Rgb le = l.illuminate(s.scene.sceneSphere, x, rng.uniform2(), &dir, &dist, &directPdfW,
                              &emPdfW, &cosL);
        if (isBlack(le)) continue;
        Ray ray;
        ray.org = x;
        ray.dir = dir;
        Hit hit;
        // Rounding of dir can make a ray aimed at a silhouette or an outer edge of the
        // light miss it; such misses must be rare.
        if (!s.scene.intersect(ray, &hit)) {
            ++misses;
            continue;
        }
        if (hit.lightId != id) continue;  // the other light is in the way
        ++checked;
        float pdfA, emPdfW2;
        Rgb le2 = s.scene.lights[hit.lightId].radianceAlong(s.scene.sceneSphere, dir, hit.pos,
                                                            hit.geoNormal, hit.uv, &pdfA, &emPdfW2);
        float pdfW2 = pdfA * hit.dist * hit.dist / std::fabs(dot(hit.geoNormal, dir));
        // The scene recomputes the hit point and normal. Rounding of dir displaces the
        // ray by ~1e-7 d from the sampled point; at grazing incidence the hit then moves
        // by that / cos along the surface, changing the cosine by ~1e-7 d / (r cos)
        // (d <= 5, radius of curvature r >= 0.75 here): relative pdf error
        // ~7e-7 / cos^2 on top of 1e-4.
        double rel = 1e-4 + 2e-6 / (cosL * cosL);
        EXPECT_NEAR(hit.dist, dist, 1e-4 * dist + 1e-6 * dist / cosL);  // shift ~1e-7 d / cos
        ASSERT_EQ(le.x, le2.x);
        ASSERT_TRUE(relNear(directPdfW, pdfW2, rel))
            << directPdfW << " vs " << pdfW2 << " cos " << cosL;
        ASSERT_TRUE(relNear(emPdfW, emPdfW2, rel)) << emPdfW << " vs " << emPdfW2;
    }
    EXPECT_GT(checked, 1000);
    EXPECT_LT(misses, checked / 100 + 1);
}

TEST(Light, SceneHitsReproduceEmitPdfs) {
    LitScene s;
    buildScene(&s);
    Rng rng(22, 1);
    int checked = 0;
    for (int i = 0; i < 4000; ++i) {
        int id = (i % 2) ? s.quadLight : s.ballLight;
        const Light& l = s.scene.lights[id];
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Vec2 rd = rng.uniform2();
        Rgb le = l.emit(s.scene.sceneSphere, rd, rng.uniform2(), &pos, &dir, &emPdfW, &pdfA, &cosL);
        if (isBlack(le) || cosL < 1e-3f) continue;
        // Trace back towards the emitted point from a point on the emitted ray.
        Ray ray;
        ray.org = pos + 0.05f * dir;
        ray.dir = -dir;
        Hit hit;
        if (!s.scene.intersect(ray, &hit) || hit.lightId != id) continue;
        if (hit.dist > 0.05f * 1.001f || hit.dist < 0.05f * 0.999f) continue;
        ++checked;
        float pdfA2, emPdfW2;
        Rgb le2 = l.radianceAlong(s.scene.sceneSphere, -dir, hit.pos, hit.geoNormal, hit.uv, &pdfA2,
                                  &emPdfW2);
        double rel = 1e-4 + 2e-6 / (cosL * cosL);  // as above
        ASSERT_EQ(le.x, le2.x);
        ASSERT_TRUE(relNear(pdfA, pdfA2, 1e-6));
        ASSERT_TRUE(relNear(emPdfW, emPdfW2, rel)) << emPdfW << " vs " << emPdfW2;
    }
    EXPECT_GT(checked, 2000);
}

// Textured area emitters (tests/data/mitsuba/textured_emitter.xml: a rectangle, a uv-mapped
// OBJ panel and a sphere): the radiance illuminate() and emit() return at a sampled point is the
// texture at the uv Scene::intersect reports there, except within rounding of a texel edge
// (nearest filtering, checkerboard squares): fewer than 1% of the samples.
TEST(Light, TexturedEmittersLookUpTheHitsUv) {
    std::unique_ptr<Scene> scene = loadMitsubaScene(
        std::string(UNIBEAM_TEST_DATA_DIR) + "/mitsuba/textured_emitter.xml", {{"res", "16"}});
    Rng rng(23, 1);
    int textured = 0;
    for (size_t id = 0; id < scene->lights.size(); ++id) {
        const Light& l = scene->lights[id];
        if (!l.radianceTexture) continue;
        ++textured;
        int checked = 0, differ = 0, emitChecked = 0, emitDiffer = 0;
        for (int i = 0; i < 4000; ++i) {
            // Receivers in front of the emitters, towards the camera.
            const Vec3 x = Vec3(-2.0f, 0.3f, 2.0f) + Vec3(4.0f, 2.5f, 3.0f) * rng.uniform3();
            Vec3 dir;
            float dist, directPdfW, emPdfW, cosL;
            Rgb le = l.illuminate(scene->sceneSphere, x, rng.uniform2(), &dir, &dist, &directPdfW,
                                  &emPdfW, &cosL);
            if (!isBlack(le)) {
                Ray ray;
                ray.org = x;
                ray.dir = dir;
                Hit hit;
                if (scene->intersect(ray, &hit) && hit.lightId == int(id) &&
                    std::fabs(hit.dist - dist) < 1e-3f * dist) {
                    ++checked;
                    float pdfA, emPdfW2;
                    const Rgb le2 = l.radianceAlong(scene->sceneSphere, dir, hit.pos, hit.geoNormal,
                                                    hit.uv, &pdfA, &emPdfW2);
                    if (!(std::fabs(le.x - le2.x) <= 1e-3f * std::max(le.x, le2.x) + 1e-6f &&
                          std::fabs(le.z - le2.z) <= 1e-3f * std::max(le.z, le2.z) + 1e-6f))
                        ++differ;
                }
            }
            Vec3 pos, out;
            float pdfA;
            le = l.emit(scene->sceneSphere, rng.uniform2(), rng.uniform2(), &pos, &out, &emPdfW,
                        &pdfA, &cosL);
            if (isBlack(le) || cosL < 1e-2f) continue;
            Ray back;
            back.org = pos + 0.05f * out;
            back.dir = -out;
            Hit hit;
            if (!scene->intersect(back, &hit) || hit.lightId != int(id)) continue;
            ++emitChecked;
            float pdfA2, emPdfW2;
            const Rgb le2 = l.radianceAlong(scene->sceneSphere, -out, hit.pos, hit.geoNormal,
                                            hit.uv, &pdfA2, &emPdfW2);
            if (!(std::fabs(le.y - le2.y) <= 1e-3f * std::max(le.y, le2.y) + 1e-6f)) ++emitDiffer;
        }
        EXPECT_GT(checked, 500) << l.name;
        EXPECT_LT(differ, checked / 100 + 1) << l.name << ": illuminate() and the hit disagree";
        EXPECT_GT(emitChecked, 1000) << l.name;
        EXPECT_LT(emitDiffer, emitChecked / 100 + 1) << l.name << ": emit() and the hit disagree";
    }
    EXPECT_EQ(textured, 3);
}

}  // namespace
}  // namespace ub
