// Surface merging (surf) on the OpenCL device against its host twin: given the same surface
// photons, surface queries and hashed grid, the kernel (kernels/surf.cl) and
// estimateSurface (src/estimators/surface_merging.cpp) return the same per-query results
// within 1e-5 relative, or for GGX lobes within 2 ulp of the half vector's cosine amplified
// by the peak of D (below) (the same per-pair function, kernels/shared/ub_surf.h, in the same
// order; the device compiler may contract multiply-adds differently and its pow/sqrt may
// differ in the last ulp). The queries cover every material type with a density (diffuse,
// Phong, rough conductor with both masking forms, rough dielectric from both sides, plastic,
// rough plastic with its coating table, Beckmann conductor and plastic, SmallUPBP's multi-lobe
// material with and without refraction, Mitsuba's principled with every lobe and anisotropic,
// principledthin)
// and a delta one (mirror:
// zero), with the geometric guard on and off and perturbed shading normals. A missing OpenCL
// platform fails the test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cl/cl_runtime.h"
#include "core/rng.h"
#include "estimators/hash_grid.h"
#include "estimators/surface_merging.h"
#include "scene/bsdf.h"

using namespace ub;

namespace {

Vec3 randomUnit(Rng& rng) {
    const float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * 3.14159265f * rng.uniform();
    const float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return Vec3(s * std::cos(phi), s * std::sin(phi), z);
}

std::vector<Material> testMaterials() {
    std::vector<Material> mats(16);
    mats[0].type = MaterialType::Diffuse;
    mats[0].diffuse = Rgb(0.7f, 0.5f, 0.3f);
    mats[1].type = MaterialType::Phong;
    mats[1].diffuse = Rgb(0.3f, 0.4f, 0.2f);
    mats[1].glossy = Rgb(0.5f, 0.4f, 0.6f);
    mats[1].exponent = 30.0f;
    mats[2].type = MaterialType::RoughConductor;
    mats[2].alpha = 0.3f;
    mats[3].type = MaterialType::RoughConductor;
    mats[3].alpha = 0.15f;
    mats[3].separableMasking = true;
    mats[4].type = MaterialType::RoughDielectric;
    mats[4].alpha = 0.25f;
    mats[4].ior = 1.5f;
    mats[5].type = MaterialType::Plastic;
    mats[5].diffuse = Rgb(0.6f, 0.2f, 0.2f);
    mats[5].specular = Rgb(0.8f);
    mats[6].type = MaterialType::RoughPlastic;
    mats[6].diffuse = Rgb(0.2f, 0.5f, 0.6f);
    mats[6].specular = Rgb(0.9f);
    mats[6].alpha = 0.2f;
    mats[7].type = MaterialType::Mirror;
    mats[8].type = MaterialType::Diffuse;  // one-sided: black from the back
    mats[8].twoSided = false;
    mats[9].type = MaterialType::RoughConductor;  // Beckmann microfacets
    mats[9].alpha = 0.3f;
    mats[9].distribution = MicrofacetDistribution::kBeckmann;
    mats[10].type = MaterialType::RoughPlastic;
    mats[10].alpha = 0.25f;
    mats[10].distribution = MicrofacetDistribution::kBeckmann;
    mats[11].type = MaterialType::MultiLobe;  // SmallUPBP's lobes with refraction
    mats[11].diffuse = Rgb(0.3f, 0.2f, 0.1f);
    mats[11].glossy = Rgb(0.2f);
    mats[11].exponent = 20.0f;
    mats[11].specular = Rgb(0.8f);
    mats[11].refract = true;
    mats[11].ior = 1.4f;
    mats[12].type = MaterialType::MultiLobe;  // and without
    mats[12].diffuse = Rgb(0.4f);
    mats[12].specular = Rgb(0.3f);
    mats[13].type = MaterialType::Principled;  // Mitsuba's principled, every lobe
    mats[13].twoSided = false;
    mats[13].diffuse = Rgb(0.7f, 0.5f, 0.3f);
    mats[13].alpha = 0.4f;
    mats[13].ior = 1.45f;
    mats[13].principled.metallic = 0.3f;
    mats[13].principled.specTrans = 0.4f;
    mats[13].principled.specTint = 0.2f;
    mats[13].principled.sheen = 0.5f;
    mats[13].principled.sheenTint = 0.3f;
    mats[13].principled.flatness = 0.4f;
    mats[13].principled.clearcoat = 0.7f;
    mats[13].principled.clearcoatGloss = 0.4f;
    mats[14] = mats[13];  // anisotropic, two-sided, without transmission
    mats[14].twoSided = true;
    mats[14].principled.specTrans = 0.0f;
    mats[14].principled.anisotropic = 0.6f;
    mats[15].type = MaterialType::PrincipledThin;  // Mitsuba's principledthin
    mats[15].twoSided = true;
    mats[15].diffuse = Rgb(0.4f, 0.7f, 0.3f);
    mats[15].alpha = 0.4f;
    mats[15].ior = 1.4f;
    mats[15].principled.specTrans = 0.4f;
    mats[15].principled.diffTrans = 0.8f;
    mats[15].principled.sheen = 0.5f;
    mats[15].principled.anisotropic = 0.3f;
    for (Material& m : mats) prepareMaterial(m);
    return mats;
}

}  // namespace

TEST(OpenClSurf, KernelEqualsHostTwinPerQueryForEveryMaterial) {
    const std::vector<Material> mats = testMaterials();
    std::vector<float> tables(mats.size() * UB_ROUGH_PLASTIC_TABLE_SIZE, 0.0f);
    for (size_t m = 0; m < mats.size(); ++m)
        std::copy(mats[m].coatingTransmittance.begin(), mats[m].coatingTransmittance.end(),
                  tables.begin() + long(m * UB_ROUGH_PLASTIC_TABLE_SIZE));

    Rng rng(1234, 5);
    // Photons in the unit cube; every 17th is a medium vertex, which surf skips.
    std::vector<LightVertex> photons(6000);
    for (size_t i = 0; i < photons.size(); ++i) {
        LightVertex& lv = photons[i];
        lv = LightVertex{};
        storeF3(lv.position, rng.uniform3());
        lv.pathLength = 1 + uint32_t(i % 4);
        storeF3(lv.throughput, Rgb(0.2f) + rng.uniform3());
        storeF3(lv.dirFix, randomUnit(rng));
        lv.contProb = 0.5f + 0.5f * rng.uniform();
        lv.dVCM = 0.1f + rng.uniform();
        lv.dVC = 0.1f + rng.uniform();
        lv.dVM = 0.1f + rng.uniform();
        lv.flags = i % 17 == 0 ? UB_LIGHT_VERTEX_IN_MEDIUM : 0u;
    }
    std::vector<ub_surface_query> queries;
    std::vector<int> materialOf;
    for (int i = 0; i < 1800; ++i) {
        const int m = i % int(mats.size());
        const Vec3 ng = randomUnit(rng);
        const Vec3 ns = normalize(ng + 0.2f * randomUnit(rng));
        const Vec3 dirFix = randomUnit(rng);
        Bsdf bsdf;
        bsdf.setGeometricGuard(i % 2 == 0);
        if (!bsdf.setup(mats[size_t(m)], dirFix, ng, ns, /*fromLight=*/false)) continue;
        queries.push_back(makeSurfaceQuery(bsdf, rng.uniform3(), 1 + i % 3,
                                           Rgb(0.5f) + rng.uniform3(), uint32_t(i),
                                           0.1f + rng.uniform(), 0.1f + rng.uniform(), 0.8f, m));
        materialOf.push_back(m);
    }
    ASSERT_GT(queries.size(), 1700u);

    const float r = 0.12f;
    HashGrid grid;
    grid.build(photons, &LightVertex::position, r);
    SurfaceMergeInput in;
    in.mis = ub_mis_make_constants(r, 1000.0f, 1, 1, UB_MIS_POWER);
    in.radius = r;
    in.normalization = ub_surf_normalization(1000.0f, r);
    in.minLength = 0;
    in.maxLength = 5;
    in.photons = &photons;
    in.queries = &queries;
    in.tables = &tables;
    std::vector<Rgb> host, device;
    size_t pairs = 0;
    estimateSurface(in, grid, &host, &pairs);
    EXPECT_GT(pairs, 20000u);

    ClRuntime cl(-1, -1, "-");
    const std::vector<ub_medium_info> media(1, ub_medium_info{});
    ClRuntime::EstimateArgs a;
    a.media = &media;
    a.mis = in.mis;
    a.radius = r;
    a.normalization = in.normalization;
    a.minLength = 0;
    a.maxLength = 5;
    cl.estimateSurf(photons, grid, tables, queries, a, &device);
    ASSERT_EQ(device.size(), host.size());
    std::vector<int> nonzero(mats.size(), 0);
    std::vector<double> maxRel(mats.size(), 0.0);
    for (size_t i = 0; i < host.size(); ++i)
        for (int c = 0; c < 3; ++c)
            if (host[i][c] > 0.0f)
                maxRel[size_t(materialOf[i])] =
                    std::max(maxRel[size_t(materialOf[i])],
                             std::fabs(double(device[i][c]) - host[i][c]) / host[i][c]);
    // Bound: 1e-5 relative; for GGX lobes 2 ulp (2^-22) of the half vector's cosine times the
    // sensitivity of D near its peak, |d ln D / d cos| ~ 4 / alpha^2 (180 at alpha 0.15), if
    // that is larger (the device's sqrt in the normalisation may differ by an ulp).
    std::vector<float> bound(mats.size(), 1e-5f);
    for (size_t m = 0; m < mats.size(); ++m) {
        const MaterialType t = mats[m].type;
        if (t == MaterialType::RoughConductor || t == MaterialType::RoughDielectric ||
            t == MaterialType::RoughPlastic)
            bound[m] = std::max(1e-5f, 0x1p-22f * 4.0f / (mats[m].alpha * mats[m].alpha));
        if (t == MaterialType::Principled ||
            t == MaterialType::PrincipledThin) {  // its sharpest lobe: GGX r^2 or the clearcoat
            const float r2 = mats[m].alpha * mats[m].alpha;
            const float cc = 0.1f + (0.001f - 0.1f) * mats[m].principled.clearcoatGloss;
            const float a = std::min(std::max(0.001f, r2), cc);
            bound[m] = std::max(1e-5f, 0x1p-22f * 4.0f / (a * a));
        }
        std::printf("material %zu: max relative difference %.3g (bound %.3g)\n", m, maxRel[m],
                    double(bound[m]));
    }
    for (size_t i = 0; i < host.size(); ++i) {
        const float rel = bound[size_t(materialOf[i])];
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(device[i][c], host[i][c], rel * std::fabs(host[i][c]) + 1e-12f)
                << "query " << i << " (material " << materialOf[i] << ") channel " << c;
        nonzero[size_t(materialOf[i])] += host[i][0] + host[i][1] + host[i][2] > 0.0f;
    }
    // Every material with a density contributes for many queries; the mirror never does.
    for (size_t m = 0; m < mats.size(); ++m) {
        if (mats[m].type == MaterialType::Mirror)
            EXPECT_EQ(nonzero[m], 0) << "material " << m;
        else
            EXPECT_GT(nonzero[m], 40) << "material " << m;
    }

    // A program specialised to some of the types (a render builds one for its scene's,
    // clBsdfTypesOption) gives the same results bit for bit for those types; the others
    // evaluate to zero there, which is why the option must name every type of the scene.
    std::vector<Material> subset;
    for (const Material& m : mats)
        if (m.type == MaterialType::Diffuse || m.type == MaterialType::Phong ||
            m.type == MaterialType::MultiLobe)
            subset.push_back(m);
    ClRuntime spec(-1, -1, "-", clBsdfTypesOption(subset));
    std::vector<Rgb> specialised;
    spec.estimateSurf(photons, grid, tables, queries, a, &specialised);
    ASSERT_EQ(specialised.size(), device.size());
    int kept = 0, dropped = 0;
    for (size_t i = 0; i < device.size(); ++i) {
        const MaterialType t = mats[size_t(materialOf[i])].type;
        const bool inSubset = std::any_of(subset.begin(), subset.end(),
                                          [&](const Material& m) { return m.type == t; });
        for (int c = 0; c < 3; ++c) {
            if (inSubset)
                ASSERT_EQ(specialised[i][c], device[i][c]) << "query " << i << " channel " << c;
            else
                ASSERT_EQ(specialised[i][c], 0.0f) << "query " << i << " channel " << c;
        }
        const bool lit = device[i][0] + device[i][1] + device[i][2] > 0.0f;
        kept += inSubset && lit;
        dropped += !inSubset && lit;
    }
    EXPECT_GT(kept, 200);
    EXPECT_GT(dropped, 200);
}
