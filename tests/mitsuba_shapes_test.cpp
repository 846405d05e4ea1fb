// Mitsuba 3's `disk`, `cylinder`, `shapegroup`/`instance` and the smooth `conductor` with a
// Fresnel term (src/scene/io/mitsuba_loader.cpp, mitsuba_bsdfs.cpp, src/scene/shapes.cpp,
// docs/mitsuba.md): the tessellated shapes have the analytic area, bounds, normals and
// Mitsuba's uvs; instances copy their group's shapes with the instance's transform; a
// conductor keeps its complex IOR; bad input gives an error naming the file and line. The
// same features in the JSON format (docs/scene-format.md) are checked at the end.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "scene/bsdf.h"
#include "scene/io/json_loader.h"
#include "scene/io/mitsuba_loader.h"
#include "scene/io/mitsuba_spectra.h"
#include "scene/shapes.h"
#include "tests/support/mitsuba_text.h"
#include "tests/support/temp_file.h"

using namespace ub;
namespace fs = std::filesystem;

namespace {

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

const char* kSensor = R"(<sensor type="perspective">
  <transform name="to_world"><lookat origin="0, 0, 9" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
    <rfilter type="box"/></film>
</sensor>
<emitter type="constant"><rgb name="radiance" value="1"/></emitter>
)";

std::string scene(const std::string& body) {
    return std::string("<scene version=\"3.0.0\">\n") + kSensor + body + "</scene>\n";
}

std::unique_ptr<Scene> load(const std::string& text) {
    return test::loadMitsubaText(text);
}

std::string errorsOf(const std::string& text) {
    return test::mitsubaErrorsOf(text);
}

void expectRgb(const Rgb& got, const Rgb& want) {
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(got[c], want[c]) << "channel " << c;
}

/// "scene.xml:L:" for the line of `text` holding the first occurrence of `marker`.
std::string at(const std::string& text, const std::string& marker) {
    const size_t pos = text.find(marker);
    EXPECT_NE(pos, std::string::npos) << marker;
    int line = 1;
    for (size_t i = 0; i < pos && i < text.size(); ++i) line += text[i] == '\n';
    return "scene.xml:" + std::to_string(line) + ":";
}

double shapeArea(const Scene& s, uint32_t shapeId) {
    double a = 0.0;
    for (uint32_t t = 0; t < s.shapes[shapeId].triangleCount; ++t) {
        Vec3 p[3];
        s.meshTriangle(shapeId, t, p);
        a += 0.5 * double(length(cross(p[1] - p[0], p[2] - p[0])));
    }
    return a;
}

Hit hitAlong(const Scene& s, const Vec3& org, const Vec3& dir) {
    Ray ray;
    ray.org = org;
    ray.dir = normalize(dir);
    Hit hit;
    EXPECT_TRUE(s.intersect(ray, &hit));
    return hit;
}

/// Mitsuba's basis around unit n (Duff et al. 2017, "Building an Orthonormal Basis,
/// Revisited"), written out here independently of core/vec.h's Frame.
void duffBasis(const Vec3& n, Vec3* s, Vec3* t) {
    const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (sign + n.z), b = n.x * n.y * a;
    *s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    *t = Vec3(b, sign + n.y * n.y * a, -n.y);
}

}  // namespace

// ---------------------------------------------------------------- tessellation

// The inscribed 512-gon: area pi (1 - 2.5e-5) for the disk and perimeter 2 pi (1 - 6.3e-6)
// for the cylinder, both below the analytic values and within the 1e-4 stated in shapes.h.
TEST(Shapes, DiskAndCylinderAreasMatchAnalyticWithin1e4) {
    const double disk = meshArea(makeDisk()), cyl = meshArea(makeCylinder());
    EXPECT_LT(disk, kPi);
    EXPECT_LT(std::fabs(disk / kPi - 1.0), 3e-5) << disk;
    EXPECT_LT(cyl, 2.0 * kPi);
    EXPECT_LT(std::fabs(cyl / (2.0 * kPi) - 1.0), 1e-5) << cyl;
    // A coarse tessellation is measurably worse (the area test can fail).
    EXPECT_GT(std::fabs(meshArea(makeDisk(32)) / kPi - 1.0), 5e-3);
}

TEST(Shapes, DiskAndCylinderNormalsAndUvsFollowMitsuba) {
    const TriangleMesh d = makeDisk(64);
    ASSERT_EQ(d.triangleCount(), 64u);
    ASSERT_EQ(d.uvs.size(), d.positions.size());
    EXPECT_TRUE(d.normals.empty());
    for (size_t t = 0; t < d.triangleCount(); ++t) {
        const Vec3& p0 = d.positions[d.indices[3 * t]];
        const Vec3 n = normalize(
            cross(d.positions[d.indices[3 * t + 1]] - p0, d.positions[d.indices[3 * t + 2]] - p0));
        EXPECT_NEAR(n.z, 1.0f, 1e-6f);
    }
    for (size_t i = 0; i < d.positions.size(); ++i) {
        const Vec3& p = d.positions[i];
        const float r = std::sqrt(p.x * p.x + p.y * p.y);
        EXPECT_NEAR(d.uvs[i].x, r, 1e-6f);  // u = r
        if (r > 0.5f) {
            // v = phi / 2 pi in [0, 1]; the seam vertex of the last wedge has v = 1.
            float phi = std::atan2(p.y, p.x);
            if (phi < 0.0f) phi += 2.0f * kPi;
            const float v = phi / (2.0f * kPi);
            EXPECT_TRUE(std::fabs(d.uvs[i].y - v) < 1e-5f ||
                        (std::fabs(d.uvs[i].y - 1.0f) < 1e-6f && v < 1e-5f))
                << i;
        }
    }
    const TriangleMesh c = makeCylinder(64);
    ASSERT_EQ(c.triangleCount(), 128u);
    ASSERT_EQ(c.normals.size(), c.positions.size());
    for (size_t i = 0; i < c.positions.size(); ++i) {
        const Vec3& p = c.positions[i];
        EXPECT_NEAR(p.x * p.x + p.y * p.y, 1.0f, 1e-6f);
        EXPECT_NEAR(length(c.normals[i] - Vec3(p.x, p.y, 0.0f)), 0.0f, 1e-6f);  // radial
        EXPECT_FLOAT_EQ(c.uvs[i].y, p.z);                                       // v = z
    }
    // The seam: the last column repeats the first position bit for bit, with u = 1.
    EXPECT_EQ(c.positions[128].x, c.positions[0].x);
    EXPECT_EQ(c.positions[128].y, c.positions[0].y);
    EXPECT_FLOAT_EQ(c.uvs[128].x, 1.0f);
    EXPECT_FLOAT_EQ(c.uvs[0].x, 0.0f);
    for (size_t t = 0; t < c.triangleCount(); ++t) {
        const Vec3& p0 = c.positions[c.indices[3 * t]];
        const Vec3& p1 = c.positions[c.indices[3 * t + 1]];
        const Vec3& p2 = c.positions[c.indices[3 * t + 2]];
        const Vec3 n = normalize(cross(p1 - p0, p2 - p0));
        const Vec3 centroid = (p0 + p1 + p2) / 3.0f;
        EXPECT_GT(dot(n, Vec3(centroid.x, centroid.y, 0.0f)), 0.99f) << t;  // outward
    }
}

TEST(Shapes, CylinderPlacementPutsTheAxisFromP0ToP1) {
    const Vec3 p0(1, 2, 3), p1(2, 0, 5);
    const Transform t = cylinderPlacement(p0, p1, 0.5f);
    EXPECT_NEAR(length(t.point(Vec3(0, 0, 0)) - p0), 0.0f, 1e-6f);
    EXPECT_NEAR(length(t.point(Vec3(0, 0, 1)) - p1), 0.0f, 1e-5f);
    EXPECT_NEAR(length(t.vector(Vec3(1, 0, 0))), 0.5f, 1e-6f);
    EXPECT_TRUE(keepsCylinderCircular(t));
    EXPECT_FALSE(keepsCylinderCircular(Transform::scale({1, 2, 1}) * t));
    EXPECT_FALSE(keepsCylinderCircular(Transform::scale({-1, 1, 1}) * t));  // mirrored
    // Along +z the frame is the identity (Mitsuba's default cylinder is its object space).
    const Transform z = cylinderPlacement(Vec3(0.0f), Vec3(0, 0, 1), 1.0f);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) EXPECT_FLOAT_EQ(z.m[i][j], i == j ? 1.0f : 0.0f);
}

// ---------------------------------------------------------------- disk

TEST(MitsubaShapes, DiskHasAreaBoundsNormalAndUvOfMitsubasDisk) {
    // Radius 2 in the plane y = 1, normal -y (rotating +z by 90 degrees about x).
    const std::string text = scene(R"(<shape type="disk">
  <transform name="to_world"><scale value="2"/><rotate x="1" angle="90"/><translate y="1"/></transform>
  <emitter type="area"><rgb name="radiance" value="1"/></emitter>
</shape>
<shape type="disk" id="flipped">
  <boolean name="flip_normals" value="true"/>
  <transform name="to_world"><translate z="-5"/></transform>
</shape>
)");
    auto s = load(text);
    ASSERT_EQ(s->shapes.size(), 2u);
    const double area = shapeArea(*s, 0);
    EXPECT_LT(area, 4.0 * kPi);
    EXPECT_LT(std::fabs(area / (4.0 * kPi) - 1.0), 1e-4);
    const Bounds3& b = s->shapes[0].bounds;
    EXPECT_NEAR(b.lo.x, -2.0f, 1e-5f);
    EXPECT_NEAR(b.hi.x, 2.0f, 1e-5f);
    EXPECT_NEAR(b.lo.z, -2.0f, 1e-4f);
    EXPECT_NEAR(b.hi.z, 2.0f, 1e-4f);
    EXPECT_NEAR(b.lo.y, 1.0f, 1e-5f);
    EXPECT_NEAR(b.hi.y, 1.0f, 1e-5f);
    // The area light covers the same triangles (power = radiance x area x pi).
    ASSERT_GE(s->shapes[0].lightId, 0);
    EXPECT_NEAR(s->lights[size_t(s->shapes[0].lightId)].totalArea, area, 1e-4 * area);
    // Object point (0.3, -0.4) is world (0.6, 1, -0.8): uv = (r, phi / 2 pi) = (0.5, 0.8524).
    const Hit h = hitAlong(*s, Vec3(0.6f, -3.0f, -0.8f), Vec3(0, 1, 0));
    EXPECT_NEAR(h.pos.y, 1.0f, 1e-5f);
    EXPECT_NEAR(h.geoNormal.y, -1.0f, 1e-6f);
    EXPECT_NEAR(h.uv.x, 0.5f, 1e-4f);
    // v: the centre vertex of each wedge carries the wedge's middle v, so v is within one
    // wedge (1/512) of Mitsuba's.
    EXPECT_NEAR(h.uv.y, (std::atan2(-0.4f, 0.3f) + 2.0f * kPi) / (2.0f * kPi), 2e-3f);
    EXPECT_EQ(s->shapes[1].name, "flipped");
    const Hit f = hitAlong(*s, Vec3(0.2f, 0.1f, -3.0f), Vec3(0, 0, -1));
    EXPECT_EQ(f.shapeId, 1u);
    EXPECT_NEAR(f.geoNormal.z, -1.0f, 1e-6f);  // flip_normals: -z
}

TEST(MitsubaShapes, DiskErrorsNameFileAndLine) {
    const std::string shear = scene(R"(<shape type="disk">
  <transform name="to_world"><matrix value="1 0.5 0 0  0 1 0 0  0 0 1 0  0 0 0 1"/></transform>
</shape>
)");
    const std::string e = errorsOf(shear);
    EXPECT_TRUE(contains(e, at(shear, "<transform name=\"to_world\"><matrix")) &&
                contains(e, "shears the disk"))
        << e;
    const std::string bad = scene(R"(<shape type="disk"><float name="radius" value="2"/></shape>
)");
    const std::string e2 = errorsOf(bad);
    EXPECT_TRUE(contains(e2, at(bad, "name=\"radius\"")) &&
                contains(e2, "unsupported parameter 'radius'"))
        << e2;
}

// ---------------------------------------------------------------- cylinder

TEST(MitsubaShapes, CylinderHasAreaBoundsSmoothNormalsAndUvOfMitsubasCylinder) {
    const std::string text = scene(R"(<shape type="cylinder">
  <point name="p0" x="1" y="0" z="0"/>
  <point name="p1" x="1" y="0" z="2"/>
  <float name="radius" value="0.5"/>
  <emitter type="area"><rgb name="radiance" value="1"/></emitter>
</shape>
)");
    auto s = load(text);
    ASSERT_EQ(s->shapes.size(), 1u);
    const double area = shapeArea(*s, 0), analytic = 2.0 * kPi * 0.5 * 2.0;
    EXPECT_LT(area, analytic);
    EXPECT_LT(std::fabs(area / analytic - 1.0), 1e-4);
    ASSERT_GE(s->shapes[0].lightId, 0);
    EXPECT_NEAR(s->lights[size_t(s->shapes[0].lightId)].totalArea, area, 1e-4 * area);
    const Bounds3& b = s->shapes[0].bounds;
    EXPECT_NEAR(b.lo.x, 0.5f, 1e-5f);
    EXPECT_NEAR(b.hi.x, 1.5f, 1e-5f);
    EXPECT_NEAR(b.lo.y, -0.5f, 1e-4f);
    EXPECT_NEAR(b.hi.y, 0.5f, 1e-4f);
    EXPECT_NEAR(b.lo.z, 0.0f, 1e-6f);
    EXPECT_NEAR(b.hi.z, 2.0f, 1e-6f);
    // A ray towards the axis at phi = 1 rad, z = 0.7: uv = (1 / 2 pi, 0.35), the shading
    // normal radial (smooth), the geometric one within half a segment (pi / 512) of it.
    const Vec3 radial(std::cos(1.0f), std::sin(1.0f), 0.0f);
    const Hit h = hitAlong(*s, Vec3(1, 0, 0.7f) + 3.0f * radial, -radial);
    EXPECT_NEAR(h.dist, 2.5f, 1e-4f);
    EXPECT_NEAR(length(h.shadingNormal - radial), 0.0f, 1e-5f);
    EXPECT_LT(length(h.geoNormal - radial), 0.01f);
    EXPECT_GT(length(h.geoNormal - radial), 1e-4f);  // flat triangles: not the smooth normal
    EXPECT_NEAR(h.uv.x, 1.0f / (2.0f * kPi), 1e-4f);
    EXPECT_NEAR(h.uv.y, 0.35f, 1e-5f);
    // The cylinder is open: a ray along the axis passes through.
    Ray axial;
    axial.org = Vec3(1, 0, -5);
    axial.dir = Vec3(0, 0, 1);
    Hit miss;
    EXPECT_FALSE(s->intersect(axial, &miss));
}

TEST(MitsubaShapes, SlantedCylinderUsesMitsubasFrameForU) {
    // Axis p0 -> p1 along d; u = 0 lies along the first vector of Mitsuba's basis around d.
    const Vec3 p0(0.5f, -0.2f, 0.3f), p1(1.5f, 1.8f, -0.7f);
    const std::string text = scene(R"(<shape type="cylinder">
  <point name="p0" x="0.5" y="-0.2" z="0.3"/>
  <point name="p1" x="1.5" y="1.8" z="-0.7"/>
  <float name="radius" value="0.4"/>
  <boolean name="flip_normals" value="true"/>
  <transform name="to_world"><translate x="1"/></transform>
</shape>
)");
    auto s = load(text);
    const Vec3 d = normalize(p1 - p0);
    Vec3 sx, ty;
    duffBasis(d, &sx, &ty);
    const float phi = 2.0f;  // u = 2 / 2 pi
    const Vec3 radial = std::cos(phi) * sx + std::sin(phi) * ty;
    const Vec3 onAxis = Vec3(1, 0, 0) + p0 + 0.25f * (p1 - p0);  // v = 0.25
    const Hit h = hitAlong(*s, onAxis + 3.0f * radial, -radial);
    EXPECT_NEAR(h.uv.x, phi / (2.0f * kPi), 1e-4f);
    EXPECT_NEAR(h.uv.y, 0.25f, 1e-4f);
    // flip_normals: the normals point to the axis (a ray from outside sees the back).
    EXPECT_NEAR(length(h.shadingNormal + radial), 0.0f, 1e-4f);
    EXPECT_LT(dot(h.geoNormal, radial), -0.99f);
}

TEST(MitsubaShapes, CylinderErrorsNameFileAndLine) {
    const std::string same = scene(R"(<shape type="cylinder">
  <point name="p0" x="1" y="1" z="1"/>
  <point name="p1" x="1" y="1" z="1"/>
</shape>
)");
    std::string e = errorsOf(same);
    EXPECT_TRUE(contains(e, at(same, "name=\"p1\"")) && contains(e, "p0 and p1 must differ")) << e;
    const std::string elliptic = scene(R"(<shape type="cylinder">
  <transform name="to_world"><scale x="1" y="2" z="1"/></transform>
</shape>
)");
    e = errorsOf(elliptic);
    EXPECT_TRUE(contains(e, at(elliptic, "<scale x=\"1\" y=\"2\"")) &&
                contains(e, "keep the cylinder circular"))
        << e;
    // A scale along the axis keeps it circular (Mitsuba takes the length from it).
    auto s = load(scene(R"(<shape type="cylinder">
  <transform name="to_world"><scale x="0.5" y="0.5" z="3"/></transform>
</shape>
)"));
    EXPECT_NEAR(shapeArea(*s, 0), 2.0 * kPi * 0.5 * 3.0, 1e-4 * 3.0 * kPi);
    const std::string zero =
        scene(R"(<shape type="cylinder"><float name="radius" value="0"/></shape>
)");
    e = errorsOf(zero);
    EXPECT_TRUE(contains(e, at(zero, "name=\"radius\""))) << e;
    // An open cylinder bounding a medium: Mitsuba's transitions are local to each crossing,
    // so it loads, with a warning that a path leaving through a gap keeps the interior medium
    // (as in Mitsuba). JSON scenes (the priority stack) refuse open boundaries
    // (medium_scene_test.cpp).
    const std::string medium = scene(R"(<shape type="cylinder">
  <bsdf type="null"/>
  <medium type="homogeneous" name="interior"><rgb name="sigma_t" value="1"/></medium>
</shape>
)");
    std::vector<Diagnostic> warnings;
    auto open = loadMitsubaSceneFromString(medium, "scene.xml", ".", {}, &warnings);
    ASSERT_TRUE(open);
    std::string w;
    for (const Diagnostic& d : warnings) w += d.format() + "\n";
    EXPECT_TRUE(contains(w, "is a medium boundary but its mesh is not closed")) << w;
    EXPECT_TRUE(contains(w,
                         "as in Mitsuba, a path that leaves through a gap keeps its interior "
                         "medium"))
        << w;
}

// ---------------------------------------------------------------- shapegroup / instance

namespace {

const char* kGroup = R"(<shape type="shapegroup" id="group">
  <shape type="cube" id="box">
    <transform name="to_world"><scale value="0.5"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf>
  </shape>
  <shape type="sphere"><point name="center" x="0" y="2" z="0"/><float name="radius" value="0.5"/></shape>
  <shape type="cylinder"><float name="radius" value="0.25"/></shape>
</shape>
)";

}  // namespace

TEST(MitsubaInstancing, InstancesCopyTheGroupsShapesWithTheirTransform) {
    auto s = load(scene(std::string(kGroup) + R"(<shape type="instance">
  <ref id="group"/>
</shape>
<shape type="instance" id="moved">
  <ref id="group"/>
  <transform name="to_world"><scale value="2"/><translate x="10"/></transform>
</shape>
<shape type="instance" id="mirrored">
  <ref id="group"/>
  <transform name="to_world"><scale x="-1" y="1" z="1"/><translate x="-10"/></transform>
</shape>
)"));
    // The group itself is not rendered: 3 instances x 3 shapes.
    ASSERT_EQ(s->shapes.size(), 9u);
    EXPECT_EQ(s->shapes[0].name, "instance 0/box");
    EXPECT_EQ(s->shapes[1].name, "instance 0/sphere 1");
    EXPECT_EQ(s->shapes[3].name, "moved/box");
    EXPECT_EQ(s->shapes[8].name, "mirrored/cylinder 2");
    // Materials are shared between instances.
    EXPECT_EQ(s->shapes[0].materialId, s->shapes[3].materialId);
    EXPECT_NE(s->shapes[0].materialId, s->shapes[1].materialId);  // default diffuse
    EXPECT_NEAR(s->shapes[3].bounds.lo.x, 9.0f, 1e-5f);
    EXPECT_NEAR(s->shapes[3].bounds.hi.x, 11.0f, 1e-5f);
    EXPECT_NEAR(shapeArea(*s, 3), 4.0 * 6.0, 1e-3);  // cube of side 1, scaled 2: 6 x 4
    EXPECT_TRUE(s->shapes[4].isSphere);
    // The moved sphere: centre (10, 4, 0), radius 1.
    const Hit h = hitAlong(*s, Vec3(10, 4, 8), Vec3(0, 0, -1));
    EXPECT_EQ(h.shapeId, 4u);
    EXPECT_NEAR(h.pos.z, 1.0f, 1e-4f);
    EXPECT_NEAR(shapeArea(*s, 5), 4.0 * 2.0 * kPi * 0.25, 1e-3);  // cylinder scaled by 2
    // Mirrored instance: the cube's normals still point outward.
    const Hit m = hitAlong(*s, Vec3(-10, 0, 8), Vec3(0, 0, -1));
    EXPECT_EQ(m.shapeId, 6u);
    EXPECT_NEAR(m.geoNormal.z, 1.0f, 1e-5f);
    const Hit side = hitAlong(*s, Vec3(-15, 0.1f, 0.1f), Vec3(1, 0, 0));
    EXPECT_EQ(side.shapeId, 6u);
    EXPECT_NEAR(side.geoNormal.x, -1.0f, 1e-5f);
}

TEST(MitsubaInstancing, BadReferencesAndMembersAreErrorsAtTheirLine) {
    const std::string missing = scene(std::string(kGroup) + R"(<shape type="instance">
  <ref id="nosuchgroup"/>
</shape>
)");
    std::string e = errorsOf(missing);
    EXPECT_TRUE(contains(e, at(missing, "<ref id=\"nosuchgroup\"")) &&
                contains(e, "no object with this id"))
        << e;

    const std::string wrong = scene(std::string(kGroup) + R"(<bsdf type="diffuse" id="paint"/>
<shape type="instance">
  <ref id="paint"/>
</shape>
<shape type="instance">
  <ref id="group"/>
  <ref id="group"/>
</shape>
)");
    e = errorsOf(wrong);
    EXPECT_TRUE(contains(e, at(wrong, "<ref id=\"paint\"")) &&
                contains(e, "<ref id=\"paint\"> names <bsdf type=\"diffuse\">") &&
                contains(e, "expected a shapegroup"))
        << e;
    EXPECT_TRUE(contains(e, "a second shapegroup")) << e;

    const std::string none = scene(R"(<shape type="instance"/>
)");
    e = errorsOf(none);
    EXPECT_TRUE(contains(e, at(none, "<shape type=\"instance\"")) &&
                contains(e, "needs the shapegroup it instantiates"))
        << e;

    const std::string nested = scene(R"(<shape type="shapegroup" id="g">
  <shape type="cube"><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
  <shape type="instance"><ref id="h"/></shape>
</shape>
<shape type="shapegroup" id="h"><shape type="cube"/></shape>
<shape type="instance"><ref id="g"/></shape>
<shape type="instance"><ref id="g"/></shape>
)");
    e = errorsOf(nested);
    EXPECT_TRUE(contains(e, at(nested, "<emitter type=\"area\">")) &&
                contains(e, "instancing of emitters is not supported"))
        << e;
    EXPECT_TRUE(contains(e, at(nested, "<shape type=\"instance\"><ref id=\"h\"")) &&
                contains(e, "nested instancing is not permitted"))
        << e;
    // The group's errors are reported once, not once per instance.
    size_t count = 0;
    for (size_t p = e.find("instancing of emitters"); p != std::string::npos;
         p = e.find("instancing of emitters", p + 1))
        ++count;
    EXPECT_EQ(count, 1u) << e;

    // A sphere cannot follow a non-uniform scale.
    const std::string stretched = scene(std::string(kGroup) + R"(<shape type="instance">
  <ref id="group"/>
  <transform name="to_world"><scale x="1" y="3" z="1"/></transform>
</shape>
)");
    e = errorsOf(stretched);
    EXPECT_TRUE(contains(e, at(stretched, "<transform name=\"to_world\"><scale x=\"1\" y=\"3\"")) &&
                contains(e, "member 'sphere 1' is a sphere"))
        << e;
}

TEST(MitsubaInstancing, CliExitsTwoNamingFileAndLine) {
    const fs::path dir = ub::test::scratchFolder("mitsuba_instancing_cli");
    const std::string text = scene(std::string(kGroup) + R"(<shape type="instance">
  <ref id="grup"/>
</shape>
)");
    std::ofstream(dir / "scene.xml") << text;
    const std::string cmd = std::string("'") + UNIBEAM_BINARY + "' info '" +
                            (dir / "scene.xml").string() + "' >'" + (dir / "out.txt").string() +
                            "' 2>&1";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2);
    std::stringstream out;
    out << std::ifstream(dir / "out.txt").rdbuf();
    EXPECT_TRUE(contains(out.str(), at(text, "<ref id=\"grup\"")) &&
                contains(out.str(), "<ref id=\"grup\">: no object with this id"))
        << out.str();
    fs::remove_all(dir);
}

// ---------------------------------------------------------------- smooth conductor

TEST(MitsubaConductor, SmoothConductorKeepsItsComplexIor) {
    auto s =
        load(scene(R"(<bsdf type="conductor" id="gold"><string name="material" value="Au"/></bsdf>
<bsdf type="conductor" id="custom">
  <rgb name="eta" value="1.2, 0.5, 0.4"/><rgb name="k" value="2, 1.5, 1"/>
  <rgb name="specular_reflectance" value="0.9, 0.8, 0.7"/>
</bsdf>
<bsdf type="conductor" id="perfect"/>
<shape type="cube"><ref id="gold"/></shape>
<shape type="cube"><ref id="custom"/></shape>
<shape type="cube"><ref id="perfect"/></shape>
)"));
    ASSERT_EQ(s->shapes.size(), 3u);
    const Material& gold = s->materials[size_t(s->shapes[0].materialId)];
    const Material& custom = s->materials[size_t(s->shapes[1].materialId)];
    const Material& perfect = s->materials[size_t(s->shapes[2].materialId)];
    Rgb eta, k;
    ASSERT_TRUE(namedConductor("Au", &eta, &k));
    EXPECT_EQ(gold.type, MaterialType::Mirror);
    EXPECT_TRUE(gold.conductorFresnel);
    expectRgb(gold.eta, eta);
    expectRgb(gold.k, k);
    EXPECT_TRUE(custom.conductorFresnel);
    expectRgb(custom.eta, Rgb(1.2f, 0.5f, 0.4f));
    expectRgb(custom.k, Rgb(2.0f, 1.5f, 1.0f));
    expectRgb(custom.specular, Rgb(0.9f, 0.8f, 0.7f));
    // Mitsuba's default material "none" stays a perfect mirror.
    EXPECT_EQ(perfect.type, MaterialType::Mirror);
    EXPECT_FALSE(perfect.conductorFresnel);
}

TEST(MitsubaConductor, BadConductorParametersAreErrors) {
    const std::string unknown = scene(R"(<shape type="cube"><bsdf type="conductor">
  <string name="material" value="Unobtainium"/>
</bsdf></shape>
)");
    std::string e = errorsOf(unknown);
    EXPECT_TRUE(contains(e, at(unknown, "Unobtainium")) &&
                contains(e, "unknown conductor material 'Unobtainium'"))
        << e;
    const std::string both = scene(R"(<shape type="cube"><bsdf type="conductor">
  <string name="material" value="Cu"/>
  <float name="eta" value="1.5"/>
</bsdf></shape>
)");
    e = errorsOf(both);
    EXPECT_TRUE(contains(e, at(both, "value=\"Cu\"")) &&
                contains(e, "give either 'material' or eta/k"))
        << e;
}

namespace {

/// Unpolarised Fresnel reflectance of a conductor eta + i k from the complex amplitude
/// coefficients (Born & Wolf), independently of kernels/shared/ub_fresnel.h's closed form.
double fresnelComplex(double cosI, double eta, double k) {
    const std::complex<double> n(eta, k), n2 = n * n;
    const double sin2 = 1.0 - cosI * cosI;
    const std::complex<double> root = std::sqrt(n2 - sin2);
    const std::complex<double> rs = (cosI - root) / (cosI + root);
    const std::complex<double> rp = (n2 * cosI - root) / (n2 * cosI + root);
    return 0.5 * (std::norm(rs) + std::norm(rp));
}

}  // namespace

// The mirror's sampled weight (f cos / pdf) is specular x F_conductor(cos theta_i) per channel,
// the same for camera and light paths, and Russian roulette follows it.
TEST(MirrorBsdf, ConductorFresnelScalesTheReflection) {
    Material m;
    m.type = MaterialType::Mirror;
    m.specular = Rgb(0.9f, 0.8f, 0.7f);
    m.conductorFresnel = true;
    m.eta = Rgb(0.18f, 1.2f, 1.37f);
    m.k = Rgb(3.42f, 1.9f, 1.77f);
    m.twoSided = false;
    const Vec3 n = normalize(Vec3(0.2f, -0.3f, 0.9f));
    const Frame frame(n);
    for (float deg : {0.0f, 30.0f, 60.0f, 85.0f})
        for (bool fromLight : {false, true}) {
            const float a = deg * kPi / 180.0f;
            const Vec3 dirFix = frame.toWorld(Vec3(std::sin(a), 0.0f, std::cos(a)));
            Bsdf b;
            ASSERT_TRUE(b.setup(m, dirFix, n, n, fromLight));
            EXPECT_TRUE(b.isDelta());
            Vec3 dir;
            float pdf = 0.0f, cosGen = 0.0f;
            const Rgb f = b.sample(Vec3(0.3f, 0.6f, 0.5f), &dir, &pdf, &cosGen, nullptr);
            ASSERT_GT(pdf, 0.0f);
            EXPECT_NEAR(length(dir - (2.0f * dot(dirFix, n) * n - dirFix)), 0.0f, 1e-5f);
            const Rgb w = f * (cosGen / pdf);
            float maxW = 0.0f;
            for (int c = 0; c < 3; ++c) {
                const double F = fresnelComplex(std::cos(double(a)), m.eta[c], m.k[c]);
                EXPECT_NEAR(w[c], m.specular[c] * F, 2e-5) << deg << " deg, channel " << c;
                maxW = std::max(maxW, w[c]);
            }
            EXPECT_NEAR(b.continuationProb(), maxW, 1e-5f);
        }
    // Without conductorFresnel the mirror is perfect: weight = specular at every angle.
    m.conductorFresnel = false;
    Bsdf b;
    ASSERT_TRUE(b.setup(m, frame.toWorld(normalize(Vec3(0.9f, 0, 0.1f))), n, n, false));
    Vec3 dir;
    float pdf = 0.0f, cosGen = 0.0f;
    const Rgb f = b.sample(Vec3(0.5f), &dir, &pdf, &cosGen, nullptr);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c] * cosGen / pdf, m.specular[c], 1e-6f);
}

// ---------------------------------------------------------------- JSON format

namespace {

std::string jsonScene(const std::string& materials, const std::string& shapes) {
    return std::string(
               R"({"camera": {"position": [0, 0, 9], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "resolution": [16, 16]},
"materials": {)") +
           materials + "},\n\"shapes\": [" + shapes +
           "],\n\"lights\": [{\"type\": \"point\", \"position\": [0, 0, 3], \"intensity\": 1}]}\n";
}

std::string jsonErrors(const std::string& text) {
    try {
        loadJsonSceneFromString(text, "scene.json", ".");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(JsonLoaderRoundShapes, DiskAndCylinderLoad) {
    auto s = loadJsonSceneFromString(
        jsonScene(R"("w": {"type": "diffuse"})",
                  R"({"type": "disk", "material": "w", "transform": {"scale": 2}},
{"type": "cylinder", "material": "w", "p0": [0, 0, 1], "p1": [0, 3, 1], "radius": 0.5, "flip_normals": true},
{"type": "cylinder", "emission": [1, 1, 1]})"),
        "scene.json", ".");
    ASSERT_EQ(s->shapes.size(), 3u);
    EXPECT_NEAR(shapeArea(*s, 0), 4.0 * kPi, 4e-4 * kPi);
    EXPECT_NEAR(shapeArea(*s, 1), 3.0 * kPi, 3e-4 * kPi);
    EXPECT_NEAR(s->shapes[1].bounds.hi.y, 3.0f, 1e-5f);
    // flip_normals: a ray from outside meets the back (normal towards the axis).
    const Hit h = hitAlong(*s, Vec3(0, 1.5f, 5), Vec3(0, 0, -1));
    EXPECT_EQ(h.shapeId, 1u);
    EXPECT_LT(h.geoNormal.z, -0.99f);
    EXPECT_NEAR(h.pos.z, 1.5f, 1e-4f);
    ASSERT_GE(s->shapes[2].lightId, 0);
    EXPECT_NEAR(s->lights[size_t(s->shapes[2].lightId)].totalArea, 2.0 * kPi, 2e-4 * kPi);
}

TEST(JsonLoaderRoundShapes, CylinderErrors) {
    std::string e = jsonErrors(
        jsonScene(R"("w": {"type": "diffuse"})",
                  R"({"type": "cylinder", "material": "w", "transform": {"scale": [1, 2, 1]}})"));
    EXPECT_TRUE(contains(e, "/shapes/0/transform") && contains(e, "keep it circular")) << e;
    e = jsonErrors(jsonScene(R"("w": {"type": "diffuse"})",
                             R"({"type": "cylinder", "material": "w", "p1": [0, 0, 0]})"));
    EXPECT_TRUE(contains(e, "/shapes/0/p1") && contains(e, "must differ")) << e;
    e = jsonErrors(jsonScene(R"("w": {"type": "diffuse"})",
                             R"({"type": "disk", "material": "w", "radius": 2})"));
    EXPECT_TRUE(contains(e, "radius")) << e;
}

TEST(JsonLoaderMirror, MirrorTakesAMetalOrEtaAndK) {
    auto s = loadJsonSceneFromString(jsonScene(R"("gold": {"type": "mirror", "metal": "gold"},
"custom": {"type": "mirror", "eta": [1.2, 0.5, 0.4], "k": [2, 1.5, 1], "reflectance": 0.9},
"plain": {"type": "mirror"})",
                                               R"({"type": "rectangle", "material": "gold"},
{"type": "rectangle", "material": "custom"},
{"type": "rectangle", "material": "plain"})"),
                                     "scene.json", ".");
    const Material& gold = s->materials[size_t(s->shapes[0].materialId)];
    const Material& custom = s->materials[size_t(s->shapes[1].materialId)];
    const Material& plain = s->materials[size_t(s->shapes[2].materialId)];
    EXPECT_TRUE(gold.conductorFresnel);
    expectRgb(gold.eta, Rgb(0.1830f, 0.4211f, 1.3734f));  // the "gold" of rough_conductor
    EXPECT_TRUE(custom.conductorFresnel);
    expectRgb(custom.k, Rgb(2.0f, 1.5f, 1.0f));
    expectRgb(custom.specular, Rgb(0.9f));
    EXPECT_FALSE(plain.conductorFresnel);
    std::string e = jsonErrors(jsonScene(R"("m": {"type": "mirror", "eta": 1.5})",
                                         R"({"type": "rectangle", "material": "m"})"));
    EXPECT_TRUE(contains(e, "/materials/m/k") && contains(e, "missing required key 'k'")) << e;
    e = jsonErrors(jsonScene(R"("m": {"type": "mirror", "metal": "golf"})",
                             R"({"type": "rectangle", "material": "m"})"));
    EXPECT_TRUE(contains(e, "unknown metal 'golf'")) << e;
}

// ---------------------------------------------------------------- sdfgrid

// The sdfgrid shape (scene/sdf_grid.h; its images against Mitsuba: mitsuba_handwritten_test):
// loads from a one-channel .vol, alone or through an instance; an emitter, a medium, a bad
// `normals` value and a three-channel grid are errors naming the shape.
TEST(MitsubaShapes, SdfGridLoadsAndItsErrorsNameTheShape) {
    const std::string dir = std::string(UNIBEAM_TEST_DATA_DIR) + "/mitsuba";
    auto errors = [&](const std::string& text) {
        try {
            loadMitsubaSceneFromString(text, "scene.xml", dir);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    auto ok = loadMitsubaSceneFromString(scene(R"(<shape type="sdfgrid">
  <string name="filename" value="volumes/sdf.vol"/>
</shape>
)"),
                                         "scene.xml", dir);
    ASSERT_EQ(ok->shapes.size(), 1u);
    EXPECT_TRUE(ok->shapes[0].isSdfGrid);
    std::string e = errors(scene(R"(<shape type="sdfgrid">
  <string name="filename" value="volumes/sdf.vol"/>
  <emitter type="area"><rgb name="radiance" value="1"/></emitter>
</shape>
)"));
    EXPECT_TRUE(contains(e, "an sdfgrid cannot emit")) << e;
    e = errors(scene(R"(<shape type="sdfgrid">
  <string name="filename" value="volumes/sdf.vol"/>
  <bsdf type="null"/>
  <medium type="homogeneous" name="interior"><rgb name="sigma_t" value="1"/></medium>
</shape>
)"));
    EXPECT_TRUE(contains(e, "an sdfgrid cannot bound a medium")) << e;
    e = errors(scene(R"(<shape type="sdfgrid">
  <string name="filename" value="volumes/sdf.vol"/>
  <string name="normals" value="flat"/>
</shape>
)"));
    EXPECT_TRUE(contains(e, "scene.xml:10:3: error")) << e;
    EXPECT_TRUE(contains(e, "normals 'flat' is not one of smooth, analytic")) << e;
    e = errors(scene(R"(<shape type="sdfgrid">
  <string name="filename" value="volumes/albedo.vol"/>
</shape>
)"));
    EXPECT_TRUE(contains(e, "has 3 channels (expected 1: signed distances)")) << e;
    e = errors(scene(R"(<shape type="sdfgrid"/>
)"));
    EXPECT_TRUE(contains(e, "needs <string name=\"filename\">")) << e;
}
