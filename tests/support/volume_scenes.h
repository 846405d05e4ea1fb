// Small scenes with participating media built in code, for the tests of the
// bidirectional volumetric integrators (tests/vbidir_test.cpp).
#pragma once

#include <memory>
#include <utility>

#include "scene/scene.h"
#include "scene/shapes.h"

namespace ub::test {

/// Volumetric furnace (the set-up of tests/vpt_test.cpp): the walls of the cube [-1, 1]^3
/// are a black diffuse surface whose inside emits Le (a one-sided area light, triangles
/// facing inwards); an imaginary, outward-facing cube [-1.001, 1.001]^3 is the boundary that
/// puts `medium` inside; vacuum outside. Camera inside at (0.1, -0.05, 0), looking at
/// (0.3, 0.2, 1). bubbleRadius > 0 adds an imaginary sphere of that radius around the camera
/// with a vacuum interior and a higher priority (nested boundaries): light tracing then
/// never connects to the camera from closer than bubbleRadius, which bounds its 1/d^2
/// factor (in a medium reaching the camera its variance is infinite).
inline std::unique_ptr<Scene> volumeFurnace(const Medium& medium, const Rgb& le, int res,
                                            float bubbleRadius = 0.0f) {
    auto scene = std::make_unique<Scene>();
    Material black;
    black.type = MaterialType::Diffuse;
    black.diffuse = Rgb(0.0f);
    int mat = scene->addMaterial(black);
    TriangleMesh cube = makeCube();
    transformMesh(cube, Transform::scale(Vec3(1.0f)));
    for (size_t t = 0; t < cube.triangleCount(); ++t)
        std::swap(cube.indices[3 * t + 1], cube.indices[3 * t + 2]);  // normals inwards
    cube.normals.clear();
    Light light;
    light.type = LightType::Area;
    light.name = "walls";
    light.radiance = le;
    for (uint32_t i : cube.indices) light.triangles.push_back(cube.positions[i]);
    int lightId = scene->addLight(light);
    int med = scene->addMedium(medium, "furnace medium");
    scene->addMesh(cube, mat, lightId, "emitting walls");
    TriangleMesh outward = makeCube();
    outward.normals.clear();
    transformMesh(outward, Transform::scale(Vec3(1.001f)));
    uint32_t b = scene->addMesh(outward, -1, -1, "medium boundary");
    scene->setMediumBoundary(b, med, 0, /*imaginary=*/true);
    const Vec3 cameraPos(0.1f, -0.05f, 0.0f);
    if (bubbleRadius > 0.0f) {
        uint32_t s = scene->addSphere(cameraPos, bubbleRadius, -1, -1, "vacuum bubble");
        scene->setMediumBoundary(s, -1, 1, /*imaginary=*/true);
    }
    scene->camera.setup(cameraPos, Vec3(0.3f, 0.2f, 1.0f), Vec3(0, 1, 0), 70.0f, res, res);
    scene->commit();
    return scene;
}

}  // namespace ub::test
