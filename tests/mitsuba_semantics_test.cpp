// Mitsuba 3's volpath semantics, which the Mitsuba XML loader selects
// (scene.h: MediumTransitions::kShapeSides, DepthCounting::kNonNullVertices;
// docs/mitsuba.md):
//  * MediumTransitions: crossing a boundary sets the medium of the side the path
//    goes to (interior or exterior of that shape), forgetting other boundaries
//    the path is inside; the priority stack (JSON, SmallUPBP) keeps them.
//  * DepthCounting: a thin sheet's transmission (a null lobe) is not a vertex of
//    the path length, in vpt and in the bidirectional engine (vbpt).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "render/integrator.h"
#include "scene/bsdf.h"
#include "scene/io/mitsuba_loader.h"
#include "scene/scene.h"
#include "tests/support/render_stats.h"

using namespace ub;
using namespace ub::test;

namespace {

// Two imaginary unit spheres on the x axis, a at the origin and b at x = 1, both with the
// purely absorbing interior medium m (sigma_t = 1); b optionally has the exterior medium e
// (sigma_t = 0.5). A ray along +x from x = -3 enters a at -1, b at 0, leaves a at 1 and b at 2.
std::unique_ptr<Scene> overlapScene(MediumTransitions mode, bool exteriorOnB) {
    auto scene = std::make_unique<Scene>();
    scene->settings.mediumTransitions = mode;
    const int m = scene->addMedium(Medium::homogeneous(Rgb(1.0f), Rgb(0.0f), 0.0f), "m");
    const int e = scene->addMedium(Medium::homogeneous(Rgb(0.5f), Rgb(0.0f), 0.0f), "e");
    const uint32_t a = scene->addSphere(Vec3(0.0f), 1.0f, -1, -1, "a");
    scene->setMediumBoundary(a, m, 0, /*imaginary=*/true);
    const uint32_t b = scene->addSphere(Vec3(1.0f, 0.0f, 0.0f), 1.0f, -1, -1, "b");
    scene->setMediumBoundary(b, m, 0, /*imaginary=*/true);
    if (exteriorOnB) scene->setExteriorMedium(b, e);
    scene->camera.setup(Vec3(0, 0, 5), Vec3(0, 0, 0), Vec3(0, 1, 0), 45.0f, 8, 8);
    scene->commit();
    return scene;
}

/// Medium ids of the segments traceMedia records along +x from x = -3 (all boundaries are
/// imaginary, so the trace runs to infinity).
std::vector<int> segmentMedia(const Scene& scene) {
    Ray ray;
    ray.org = Vec3(-3.0f, 0.0f, 0.0f);
    ray.dir = Vec3(1.0f, 0.0f, 0.0f);
    MediumStack stack = scene.mediumStackAt(ray.org);
    MediumTrace trace;
    Hit hit;
    scene.traceMedia(ray, &stack, &trace, &hit);
    EXPECT_FALSE(trace.hitSurface);
    std::vector<int> ids;
    for (int k = 0; k < trace.count; ++k) ids.push_back(trace.segments[k].mediumId);
    return ids;
}

}  // namespace

TEST(MediumTransitions, LeavingAnOverlappedShapeGivesItsExteriorNotTheOtherShape) {
    // Segments [-3,-1] [-1,0] [0,1] [1,2] [2,inf).
    auto stack = overlapScene(MediumTransitions::kPriorityStack, false);
    EXPECT_EQ(segmentMedia(*stack), (std::vector<int>{-1, 0, 0, 0, -1}));
    auto sides = overlapScene(MediumTransitions::kShapeSides, false);
    EXPECT_EQ(segmentMedia(*sides), (std::vector<int>{-1, 0, 0, -1, -1}));
    auto sidesExt = overlapScene(MediumTransitions::kShapeSides, true);
    EXPECT_EQ(segmentMedia(*sidesExt), (std::vector<int>{-1, 0, 0, -1, 1}));

    // Shadow transmittance -3 -> 3 (exact: homogeneous, absorbing): optical depth 3 with the
    // stack, 2 with Mitsuba's rule, 2 + 0.5 with b's exterior medium on [2, 3].
    auto shadow = [](const Scene& s) {
        const Vec3 from(-3.0f, 0.0f, 0.0f), to(3.0f, 0.0f, 0.0f);
        MediumShadow sh =
            s.shadowTransmittance(from, Vec3(0.0f), s.mediumStackAt(from), to, Vec3(0.0f));
        EXPECT_FALSE(sh.blocked);
        return sh.transmittance.x;
    };
    EXPECT_NEAR(shadow(*stack), std::exp(-3.0f), 1e-5f);
    EXPECT_NEAR(shadow(*sides), std::exp(-2.0f), 1e-5f);
    EXPECT_NEAR(shadow(*sidesExt), std::exp(-2.5f), 1e-5f);

    // Points: inside the overlap and inside b only the medium is m in both modes; the
    // camera, outside every boundary, is in vacuum.
    for (const Scene* s : {stack.get(), sides.get()}) {
        EXPECT_EQ(s->mediumStackAt(Vec3(0.5f, 0.0f, 0.0f)).mediumId(), 0);
        EXPECT_EQ(s->mediumStackAt(Vec3(1.5f, 0.0f, 0.0f)).mediumId(), 0);
        EXPECT_EQ(s->cameraMediumStack.mediumId(), -1);
    }
}

TEST(MediumTransitions, ShapeSidesSetTheMediumOfTheOutgoingSideOnReflection) {
    // A path inside b in vacuum (it left a there) reflects off b's inner wall at x = 2:
    // Mitsuba sets the interior medium of b for the reflected direction; the stack keeps
    // what it had (reflection stays on the same side).
    for (MediumTransitions mode :
         {MediumTransitions::kPriorityStack, MediumTransitions::kShapeSides}) {
        auto s = overlapScene(mode, false);
        Ray ray;
        ray.org = Vec3(1.5f, 0.0f, 0.0f);
        ray.dir = Vec3(1.0f, 0.0f, 0.0f);
        Hit hit;
        ASSERT_TRUE(s->intersect(ray, &hit));
        ASSERT_EQ(hit.shapeId, 1u);
        MediumStack stack;
        stack.reset(-1);
        const Vec3 dirFix(-1.0f, 0.0f, 0.0f), dirGen = normalize(Vec3(-1.0f, 0.2f, 0.0f));
        ASSERT_TRUE(s->crossSurface(hit, dirFix, dirGen, &stack));
        EXPECT_EQ(stack.mediumId(), mode == MediumTransitions::kShapeSides ? 0 : -1);
        // Transmission out of b: its exterior (vacuum) with either rule.
        stack.reset(-1);
        stack.push(1, 0, 0);
        ASSERT_TRUE(s->crossSurface(hit, dirFix, Vec3(1.0f, 0.0f, 0.0f), &stack));
        EXPECT_EQ(stack.mediumId(), -1);
    }
}

TEST(MediumTransitions, ExteriorMediaNeedShapeSides) {
    // The priority stack has no notion of an exterior medium: a scene giving one is rejected.
    Scene scene;
    const int m = scene.addMedium(Medium::homogeneous(Rgb(1.0f), Rgb(0.0f), 0.0f), "m");
    const uint32_t a = scene.addSphere(Vec3(0.0f), 1.0f, -1, -1, "a");
    scene.setMediumBoundary(a, -1, 0, true);
    scene.setExteriorMedium(a, m);
    scene.camera.setup(Vec3(0, 0, 5), Vec3(0, 0, 0), Vec3(0, 1, 0), 45.0f, 8, 8);
    std::vector<MediumIssue> issues = scene.mediumIssues();
    ASSERT_EQ(issues.size(), 1u);
    EXPECT_NE(issues[0].message.find("exterior medium"), std::string::npos) << issues[0].message;
    EXPECT_THROW(scene.commit(), InputError);
}

namespace {

// A camera looking along -z at a thin dielectric sheet (ior 1.5, z = 1) in front of an area
// light (z = 0, radiance Le, facing +z) that fills the whole (narrow, 6 degree) view.
std::unique_ptr<Scene> thinSheetScene(int maxDepth) {
    const std::string xml = R"(<scene version="3.0.0">
<integrator type="volpath"><integer name="max_depth" value=")" +
                            std::to_string(maxDepth) + R"("/></integrator>
<sensor type="perspective">
  <float name="fov" value="6"/>
  <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>
    <rfilter type="box"/></film>
</sensor>
<shape type="rectangle">
  <bsdf type="thindielectric"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>
  <transform name="to_world"><scale value="3"/><translate z="1"/></transform>
</shape>
<shape type="rectangle">
  <emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter>
  <transform name="to_world"><scale value="3"/></transform>
</shape>
</scene>
)";
    return loadMitsubaSceneFromString(xml, "thin.xml", ".");
}

BlockStats renderThin(const Scene& scene, const char* algorithm, int maxLength) {
    RenderOptions o;
    o.algorithm = algorithm;
    o.maxPathLength = maxLength;
    o.seed = 3;
    auto integrator = makeIntegrator(scene, o);
    return renderBlockStats(*integrator, 64, 8);
}

}  // namespace

TEST(DepthCounting, ThinSheetTransmissionIsNotAVertex) {
    // Seen through the sheet the light has radiance Le (1 - R') with R' = 2r / (1 + r), r the
    // Fresnel reflectance at normal incidence ((0.5 / 2.5)^2 = 0.04; within 3 degrees of
    // normal it changes by < 1e-5), so 0.923077 Le. With Mitsuba's depth counting
    // (max_depth 1: emitters seen directly) the transmission is no vertex and the light
    // is seen; counting every vertex it takes max length 2, and max length 1 gives black.
    const float expected = 1.0f - 0.08f / 1.04f;
    const Rgb le(1.0f, 2.0f, 3.0f);
    auto mitsuba = thinSheetScene(1);
    ASSERT_EQ(mitsuba->settings.depthCounting, DepthCounting::kNonNullVertices);
    auto counted = thinSheetScene(1);
    counted->settings.depthCounting = DepthCounting::kAllVertices;  // read at integrator set-up
    for (const char* algorithm : {"vpt", "vbpt"}) {
        // Each sample is Le or 0 (transmitted or reflected into nothing), so 64 iterations of
        // 64 pixels give a standard error of sqrt(p (1 - p) / 4096) Le = 0.0042 Le; the bound
        // is 5 measured standard errors of the iteration means.
        for (int run = 0; run < 2; ++run) {
            const Scene& s = run == 0 ? *mitsuba : *counted;
            const int maxLength = run == 0 ? 1 : 2;
            BlockStats st = renderThin(s, algorithm, maxLength);
            for (int c = 0; c < 3; ++c) {
                std::printf(
                    "[ depth    ] %s %s max %d: channel %d mean %.5f expected %.5f "
                    "stderr %.5f\n",
                    algorithm, run == 0 ? "non-null" : "all", maxLength, c, st.imageMean(c),
                    expected * le[c], st.imageStdErr(c));
                EXPECT_NEAR(st.imageMean(c), expected * le[c], 5.0 * st.imageStdErr(c))
                    << algorithm << " run " << run;
                EXPECT_GT(st.imageStdErr(c), 0.0) << algorithm;
                EXPECT_LT(st.imageStdErr(c), 0.01 * le[c]) << algorithm;
            }
        }
        // Every vertex counted, max length 1: only paths of one segment, which end on the
        // sheet (it does not emit): exactly black.
        BlockStats black = renderThin(*counted, algorithm, 1);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(black.imageMean(c), 0.0) << algorithm;
    }
}

namespace {

// Both Mitsuba semantics in a scene with media, for vpt and vbpt (which must agree): a null
// sphere A (radius 1) of thin fog m1 holds a thindielectric sphere B (radius 0.5) of dense
// medium m2 whose exterior is m1 (Mitsuba's rule; the priority stack rejects exterior media),
// above a diffuse floor, lit by an area light above A. max_depth 4 makes the depth counting
// matter: light reaches the inside of B only through B's null lobe.
std::unique_ptr<Scene> nestedThinScene() {
    const std::string xml = R"(<scene version="3.0.0">
<integrator type="volpath"><integer name="max_depth" value="4"/></integrator>
<sensor type="perspective">
  <float name="fov" value="45"/>
  <transform name="to_world"><lookat origin="0, 0.5, 4" target="0, -0.3, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
    <rfilter type="box"/></film>
</sensor>
<medium id="m1" type="homogeneous"><rgb name="sigma_t" value="0.5"/><rgb name="albedo" value="0.8"/></medium>
<medium id="m2" type="homogeneous"><rgb name="sigma_t" value="3, 2, 1"/><rgb name="albedo" value="0.95"/></medium>
<shape type="sphere"><float name="radius" value="1"/><bsdf type="null"/><ref id="m1" name="interior"/></shape>
<shape type="sphere"><float name="radius" value="0.5"/>
  <bsdf type="thindielectric"><float name="int_ior" value="1.5"/></bsdf>
  <ref id="m2" name="interior"/><ref id="m1" name="exterior"/></shape>
<shape type="rectangle"><bsdf type="diffuse"/>
  <transform name="to_world"><scale value="4"/><rotate x="1" angle="-90"/><translate y="-1.2"/></transform>
</shape>
<shape type="rectangle">
  <emitter type="area"><rgb name="radiance" value="4"/></emitter>
  <transform name="to_world"><scale value="1.5"/><rotate x="1" angle="90"/><translate y="2"/></transform>
</shape>
</scene>
)";
    return loadMitsubaSceneFromString(xml, "nested.xml", ".");
}

}  // namespace

TEST(DepthCounting, VbptAgreesWithVptWithThinSheetsAndExteriorMedia) {
    auto scene = nestedThinScene();
    ASSERT_EQ(scene->settings.mediumTransitions, MediumTransitions::kShapeSides);
    RenderOptions o;
    o.maxPathLength = scene->settings.maxPathLength;
    o.seed = 5;
    o.algorithm = "vpt";
    auto vpt = makeIntegrator(*scene, o);
    o.algorithm = "vbpt";
    auto vbpt = makeIntegrator(*scene, o);
    // 4x4 blocks of 4x4 pixels; per-iteration block means are independent, so their standard
    // errors give z-scores; 48 tests at family-wise alpha 0.001 (Sidak-adjusted min p).
    BlockStats a = renderBlockStats(*vpt, 512, 4);
    BlockStats b = renderBlockStats(*vbpt, 512, 4);
    Agreement g = compare(b, a);
    std::printf("[ depth    ] vbpt vs vpt, thin sheet + exterior media: %s\n", g.report.c_str());
    EXPECT_GT(g.sidakMinP, 0.001) << g.report;
    for (int c = 0; c < 3; ++c) {
        EXPECT_LT(std::fabs(g.meanZ[c]), 4.0) << g.report;
        EXPECT_GT(a.imageMean(c), 0.01);  // not a black image
    }
}
