// The recursive MIS weights of kernels/shared/ub_mis.h (Georgiev et al. 2012,
// tech. report "Implementing VCM") against weights computed from the explicit
// area pdfs of every technique that could have sampled a path
// (tests/support/mis_path.h, docs/mis.md, "Brute-force weights").
//
// Tolerance: the recursion runs in float, the reference in double. Each weight
// is a ratio of sums of products of < 20 positive factors, each rounded with
// relative error 2^-24, so the float error stays far below 1e-5 for the
// ranges drawn here (pdfs, cosines and distances within [0.05, 5]); 1e-4
// (absolute, weights lie in [0,1]) leaves a 10x margin and still catches any
// missing factor (those change weights by O(0.01..1)).
#include <gtest/gtest.h>

#include "core/rng.h"
#include "tests/support/mis_path.h"

using namespace ub;
using namespace ub::test;

namespace {

float uniformIn(Rng& rng, float lo, float hi) {
    return lo + (hi - lo) * rng.uniform();
}

// A random path with k segments and primitives in moderate ranges. Specular
// vertices use equal forward/reverse lobe probabilities, as delta BSDFs do.
MisPath randomPath(Rng& rng, int k, MisLightKind kind, float specularProb) {
    MisPath p;
    p.lightKind = kind;
    p.lightPickProb = 1.0f / float(1 + int(rng.uniform() * 3));
    p.emitPosPdf = uniformIn(rng, 0.1f, 5.0f);
    p.emitDirPdfW = uniformIn(rng, 0.05f, 2.0f);
    p.directPdfA = uniformIn(rng, 0.1f, 5.0f);
    p.cosLight = uniformIn(rng, 0.1f, 1.0f);
    if (kind == MisLightKind::Point) {
        p.emitPosPdf = 1;
        p.directPdfA = 1;
        p.cosLight = 1;
        p.emitDirPdfW = 0.25f / kPi;
    } else if (kind == MisLightKind::Directional) {
        p.emitDirPdfW = 1;
        p.directPdfA = 1;
        p.cosLight = 1;
    } else if (kind == MisLightKind::Environment) {
        p.directPdfA = p.emitDirPdfW;  // illuminate and emit share the direction pdf
        p.cosLight = 1;
    }
    p.dist.assign(k + 1, 0);
    for (int i = 1; i <= k; ++i) p.dist[i] = uniformIn(rng, 0.2f, 3.0f);
    p.v.assign(k, MisVertex{});
    for (int i = 1; i < k; ++i) {
        MisVertex& x = p.v[i];
        x.cosIn = uniformIn(rng, 0.1f, 1.0f);
        x.cosOut = uniformIn(rng, 0.1f, 1.0f);
        x.cont = uniformIn(rng, 0.5f, 1.0f);
        x.specular = rng.uniform() < specularProb;
        if (x.specular) {
            x.pdfFwdW = x.pdfRevW = uniformIn(rng, 0.3f, 1.0f);
        } else {
            x.pdfFwdW = uniformIn(rng, 0.05f, 3.0f);
            x.pdfRevW = uniformIn(rng, 0.05f, 3.0f);
        }
    }
    p.cameraPdfW = uniformIn(rng, 0.5f, 4.0f) * 1000.0f;  // d_img^2 / cos^3 ~ 10^3 at 64x64
    return p;
}

struct NamedConfig {
    const char* name;
    MisConfig cfg;
};

std::vector<NamedConfig> configs() {
    std::vector<NamedConfig> out;
    for (ub_uint h : {UB_MIS_POWER, UB_MIS_BALANCE}) {
        MisConfig bpt, bpm, vcm;
        bpt.useVM = false;
        bpm.useVC = false;
        bpt.heuristic = bpm.heuristic = vcm.heuristic = h;
        // Radius chosen so that eta = N_L pi r^2 ~ 8: merging and connection pdfs compete.
        vcm.radius = bpm.radius = bpt.radius = 0.05f;
        out.push_back({h == UB_MIS_POWER ? "bpt/power" : "bpt/balance", bpt});
        out.push_back({h == UB_MIS_POWER ? "bpm/power" : "bpm/balance", bpm});
        out.push_back({h == UB_MIS_POWER ? "vcm/power" : "vcm/balance", vcm});
    }
    return out;
}

const MisLightKind kKinds[] = {MisLightKind::Area, MisLightKind::Point, MisLightKind::Directional,
                               MisLightKind::Environment};

}  // namespace

TEST(MisBruteForce, RecursiveWeightsEqualExplicitPdfWeights) {
    Rng rng(42, 7);
    int compared = 0;
    for (const NamedConfig& nc : configs()) {
        for (int n = 0; n < 3000; ++n) {
            int k = 2 + int(rng.uniform() * 7);
            MisLightKind kind = kKinds[n % 4];
            MisPath p = randomPath(rng, k, kind, 0.3f);
            auto ref = bruteForceWeights(p, nc.cfg);
            auto rec = recursiveWeights(p, nc.cfg);
            ASSERT_EQ(ref.size(), rec.size());
            for (size_t t = 0; t < ref.size(); ++t) {
                ASSERT_NEAR(rec[t].weight, ref[t].weight, 1e-4)
                    << nc.name << " k=" << k << " light kind " << int(kind) << " technique "
                    << ref[t].name() << " (path " << n << ")";
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 50000);
}

TEST(MisBruteForce, WeightsOfOnePathSumToOne) {
    Rng rng(43, 7);
    for (const NamedConfig& nc : configs()) {
        for (int n = 0; n < 3000; ++n) {
            int k = 2 + int(rng.uniform() * 7);
            MisPath p = randomPath(rng, k, kKinds[n % 4], 0.3f);
            auto rec = recursiveWeights(p, nc.cfg);
            if (rec.empty()) continue;  // e.g. delta light seen only through mirrors
            double sum = 0;
            for (const auto& t : rec) sum += t.weight;
            ASSERT_NEAR(sum, 1.0, 1e-4) << nc.name << " k=" << k << " path " << n;
        }
    }
}

// With connection enabled, dVM (eta times SmallVCM's dVM) = dVC at every vertex: same
// initial value [TR (33)], same recursion [TR (34), (35)] (Moonen & Jalba's d_pde = d_bpt).
TEST(MisBruteForce, MergePartialIsConnectionPartialOverEta) {
    Rng rng(44, 7);
    ub_mis_constants c = ub_mis_make_constants(0.05f, 1000.0f, 1, 1, UB_MIS_POWER);
    for (int n = 0; n < 1000; ++n) {
        MisPath p = randomPath(rng, 8, MisLightKind::Area, 0.3f);
        ub_mis_partials lp =
            ub_mis_init_light(c, p.directPdfA, p.emitPosPdf * p.emitDirPdfW, p.cosLight, 0, 1);
        for (int i = 1; i < 8; ++i) {
            const MisVertex& x = p.v[i];
            lp = ub_mis_at_hit(c, lp, p.dist[i], x.cosIn, 1);
            ASSERT_NEAR(lp.dVM, lp.dVC, 1e-5f * lp.dVM + 1e-30f);
            lp = ub_mis_scatter(c, lp, x.cosOut, x.pdfFwdW * x.cont, x.pdfRevW * x.cont, x.specular,
                                ub_mis_merge_factor(c, x.medium, 0));
        }
    }
}

// ---- Medium vertices (vlt, vbpt) ----------------------------------------------------
//
// Random paths whose vertices are medium vertices with probability 0.4 (cosines 1, equal
// phase pdfs in both directions, never specular) and whose segments carry random
// free-flight pdfs: a medium end gets a scatter density times pass probabilities in
// [0.02, 3] (per unit length), a surface end a pass probability in [0.02, 1], or exactly 1
// (vacuum) for a third of the surface-to-surface segments. The two directions of a segment
// get independent values, so every factor must sit in the right place. Configurations:
// bpt (power, balance) -- vbpt's techniques; merging in media is UPBP's, not tested here.
// Tolerance 1e-4 as above (the extra factors are of the same magnitude).
namespace {

void addMedia(Rng& rng, MisPath* p, float mediumProb) {
    const int k = p->k();
    for (int i = 1; i < k; ++i) {
        MisVertex& x = p->v[i];
        if (rng.uniform() >= mediumProb) continue;
        x.medium = true;
        x.specular = false;
        x.cosIn = x.cosOut = 1.0f;
        x.pdfFwdW = x.pdfRevW = uniformIn(rng, 0.02f, 4.0f);  // HG: its own adjoint
        x.cont = uniformIn(rng, 0.3f, 1.0f);
    }
    p->distFwd.assign(size_t(k + 1), 1.0f);
    p->distRev.assign(size_t(k + 1), 1.0f);
    auto inMedium = [&](int i) { return i >= 1 && i <= k - 1 && p->v[i].medium; };
    for (int i = 1; i <= k; ++i) {
        const bool endMedium = inMedium(i), startMedium = inMedium(i - 1);
        const bool vacuum = !endMedium && !startMedium && rng.uniform() < 0.33f;
        if (vacuum) continue;
        p->distFwd[size_t(i)] =
            endMedium ? uniformIn(rng, 0.02f, 3.0f) : uniformIn(rng, 0.02f, 1.0f);
        p->distRev[size_t(i)] =
            startMedium ? uniformIn(rng, 0.02f, 3.0f) : uniformIn(rng, 0.02f, 1.0f);
    }
}

/// Pass probabilities for the beam estimators: a segment ending at a medium vertex passes
/// it with a probability in [0.02, 1] (independent of its stop density), a segment ending
/// on a surface passes with its distance pdf (they are the same event); and a random
/// sin(theta) at each medium vertex.
void addBeamData(Rng& rng, MisPath* p) {
    const int k = p->k();
    auto inMedium = [&](int i) { return i >= 1 && i <= k - 1 && p->v[size_t(i)].medium; };
    p->passFwd = p->distFwd;
    p->passRev = p->distRev;
    for (int i = 1; i <= k; ++i) {
        if (inMedium(i)) p->passFwd[size_t(i)] = uniformIn(rng, 0.02f, 1.0f);
        if (inMedium(i - 1)) p->passRev[size_t(i)] = uniformIn(rng, 0.02f, 1.0f);
    }
    for (int i = 1; i < k; ++i)
        if (p->v[size_t(i)].medium) p->v[size_t(i)].sinTheta = uniformIn(rng, 0.05f, 1.0f);
}

std::vector<NamedConfig> bptConfigs() {
    std::vector<NamedConfig> out;
    for (const NamedConfig& nc : configs())
        if (!nc.cfg.useVM) out.push_back(nc);
    return out;
}

}  // namespace

TEST(MisBruteForce, MediumVerticesRecursiveWeightsEqualExplicitPdfWeights) {
    Rng rng(45, 7);
    int compared = 0, mediumVertices = 0;
    for (const NamedConfig& nc : bptConfigs()) {
        for (int n = 0; n < 4000; ++n) {
            int k = 2 + int(rng.uniform() * 7);
            MisLightKind kind = kKinds[n % 4];
            MisPath p = randomPath(rng, k, kind, 0.2f);
            addMedia(rng, &p, 0.4f);
            for (int i = 1; i < k; ++i) mediumVertices += p.v[i].medium;
            auto ref = bruteForceWeights(p, nc.cfg);
            auto rec = recursiveWeights(p, nc.cfg);
            ASSERT_EQ(ref.size(), rec.size());
            double sum = 0;
            for (size_t t = 0; t < ref.size(); ++t) {
                ASSERT_NEAR(rec[t].weight, ref[t].weight, 1e-4)
                    << nc.name << " k=" << k << " light kind " << int(kind) << " technique "
                    << ref[t].name() << " (path " << n << ")";
                sum += rec[t].weight;
                ++compared;
            }
            if (!rec.empty()) ASSERT_NEAR(sum, 1.0, 1e-4) << nc.name << " k=" << k;
        }
    }
    EXPECT_GT(compared, 30000);
    EXPECT_GT(mediumVertices, 10000);
}

// UPBP point estimators (kernels/shared/ub_mis.h, merging factors per vertex): surface
// merging at surface vertices and pp3d at medium vertices, with and without connections,
// and pp3d alone. Every recursive weight equals the explicit-pdf weight, where a pp3d merge
// at medium vertex x_i has the pdf (prod_{j<=i} a_j)(prod_{j>=i} b_j) N_L (4/3) pi r^3.
TEST(MisBruteForce, PointEstimatorsInMediaMatchExplicitPdfWeights) {
    Rng rng(47, 7);
    struct Upbp {
        const char* name;
        bool vc, surf, pp3d;
    };
    const Upbp kSets[] = {{"bpt+surf+pp3d", true, true, true},
                          {"bpt+pp3d", true, false, true},
                          {"surf+pp3d", false, true, true},
                          {"pp3d", false, false, true}};
    int compared = 0, pp3dMerges = 0;
    for (ub_uint h : {UB_MIS_POWER, UB_MIS_BALANCE})
        for (const Upbp& set : kSets) {
            MisConfig cfg;
            cfg.heuristic = h;
            cfg.useVC = set.vc;
            cfg.useVM = set.surf;
            cfg.usePP3D = set.pp3d;
            cfg.radiusPP3D = 0.08f;  // eta_pp3d = N_L 4/3 pi r^3 ~ 2: competes with the others
            for (int n = 0; n < 3000; ++n) {
                int k = 2 + int(rng.uniform() * 7);
                MisLightKind kind = kKinds[n % 4];
                MisPath p = randomPath(rng, k, kind, 0.2f);
                addMedia(rng, &p, 0.5f);
                auto ref = bruteForceWeights(p, cfg);
                auto rec = recursiveWeights(p, cfg);
                ASSERT_EQ(ref.size(), rec.size());
                double sum = 0;
                for (size_t t = 0; t < ref.size(); ++t) {
                    ASSERT_NEAR(rec[t].weight, ref[t].weight, 1e-4)
                        << set.name << (h == UB_MIS_POWER ? "/power" : "/balance") << " k=" << k
                        << " light kind " << int(kind) << " technique " << ref[t].name()
                        << " (path " << n << ")";
                    sum += rec[t].weight;
                    ++compared;
                    pp3dMerges += ref[t].merge && p.v[size_t(ref[t].index)].medium;
                }
                if (!rec.empty()) ASSERT_NEAR(sum, 1.0, 1e-4) << set.name << " k=" << k;
            }
        }
    EXPECT_GT(compared, 40000);
    EXPECT_GT(pp3dMerges, 10000);
}

// Every UPBP estimator (kernels/shared/ub_mis_volume.h): the recursive weights, with the
// beam techniques' deferred factors, equal the explicit-pdf weights of UPBP eq. (8) for
// subsets with and without connections, short and long photon and query beams, power and
// balance heuristic; one path's weights sum to 1. Radii make every eta of order 1 so that
// the techniques compete (N_L = 1000, N_B = 100).
TEST(MisBruteForce, BeamEstimatorsInMediaMatchExplicitPdfWeights) {
    Rng rng(48, 7);
    struct Upbp {
        const char* name;
        bool vc, surf, pp3d, pb2d, bp2d, bb1d;
    };
    const Upbp kSets[] = {{"all", true, true, true, true, true, true},
                          {"bpt+pb2d", true, false, false, true, false, false},
                          {"bpt+bp2d", true, false, false, false, true, false},
                          {"bpt+bb1d", true, false, false, false, false, true},
                          {"pb2d+bb1d", false, false, false, true, false, true},
                          {"bb1d", false, false, false, false, false, true},
                          {"surf+pp3d+bp2d", false, true, true, false, true, false}};
    int compared = 0, beamMerges = 0;
    for (ub_uint h : {UB_MIS_POWER, UB_MIS_BALANCE})
        for (int beams = 0; beams < 4; ++beams)
            for (const Upbp& set : kSets) {
                MisConfig cfg;
                cfg.heuristic = h;
                cfg.useVC = set.vc;
                cfg.useVM = set.surf;
                cfg.usePP3D = set.pp3d;
                cfg.usePB2D = set.pb2d;
                cfg.useBP2D = set.bp2d;
                cfg.useBB1D = set.bb1d;
                cfg.shortPhotonBeams = (beams & 1) != 0;
                cfg.shortQueryBeams = (beams & 2) != 0;
                cfg.radiusPP3D = 0.08f;
                cfg.radiusPB2D = 0.02f;   // N_L pi r^2 ~ 1.3
                cfg.radiusBP2D = 0.06f;   // N_B pi r^2 ~ 1.1
                cfg.radiusBB1D = 0.005f;  // N_B 2 r ~ 1
                for (int n = 0; n < 600; ++n) {
                    int k = 2 + int(rng.uniform() * 7);
                    MisLightKind kind = kKinds[n % 4];
                    MisPath p = randomPath(rng, k, kind, 0.2f);
                    addMedia(rng, &p, 0.5f);
                    addBeamData(rng, &p);
                    auto ref = bruteForceWeights(p, cfg);
                    auto rec = recursiveWeights(p, cfg);
                    ASSERT_EQ(ref.size(), rec.size());
                    double sum = 0;
                    for (size_t t = 0; t < ref.size(); ++t) {
                        ASSERT_NEAR(rec[t].weight, ref[t].weight, 1e-4)
                            << set.name << (h == UB_MIS_POWER ? "/power" : "/balance") << " beams "
                            << beams << " k=" << k << " light kind " << int(kind) << " technique "
                            << ref[t].name() << " (path " << n << ")";
                        sum += rec[t].weight;
                        ++compared;
                        beamMerges += ref[t].tech > 0;
                    }
                    if (!rec.empty()) ASSERT_NEAR(sum, 1.0, 1e-4) << set.name << " k=" << k;
                }
            }
    EXPECT_GT(compared, 50000);
    EXPECT_GT(beamMerges, 20000);
}

// Without media the media-aware updates reduce to the surface ones exactly.
TEST(MisBruteForce, MediaUpdatesWithUnitDistancePdfsAreTheSurfaceUpdates) {
    Rng rng(46, 7);
    ub_mis_constants c = ub_mis_make_constants(0.05f, 1000.0f, 1, 1, UB_MIS_POWER);
    for (int n = 0; n < 1000; ++n) {
        ub_mis_partials p = {uniformIn(rng, 0.1f, 5.0f), uniformIn(rng, 0.1f, 5.0f),
                             uniformIn(rng, 0.1f, 5.0f)};
        float d = uniformIn(rng, 0.1f, 3.0f), cosFix = uniformIn(rng, 0.1f, 1.0f);
        ub_mis_partials a = ub_mis_at_hit(c, p, d, cosFix, n % 2);
        ub_mis_partials b = ub_mis_at_hit_media(c, p, d, cosFix, n % 2, 1.0f, 1.0f);
        ASSERT_FLOAT_EQ(a.dVCM, b.dVCM);
        ASSERT_FLOAT_EQ(a.dVC, b.dVC);
        ASSERT_FLOAT_EQ(a.dVM, b.dVM);
    }
}

// Hand-checked special cases of the technique sets.
TEST(MisBruteForce, TechniqueSetsFollowSmallVcm) {
    MisPath p;
    p.dist = {0, 1, 1, 1};
    p.v.assign(3, MisVertex{});
    p.v[1].specular = true;
    MisConfig bpm;
    bpm.useVC = false;
    // x_1 specular, x_2 diffuse: BPM merges at x_2 only; the camera hit is not a BPM technique.
    auto t = validTechniques(p, bpm);
    ASSERT_EQ(t.size(), 1u);
    EXPECT_TRUE(t[0].merge);
    EXPECT_EQ(t[0].index, 2);
    // BPT: camera hit, NEE impossible (x_1 specular), s=2 impossible, light tracing from x_2.
    MisConfig bpt;
    bpt.useVM = false;
    t = validTechniques(p, bpt);
    ASSERT_EQ(t.size(), 2u);
    EXPECT_EQ(t[0].index, 0);
    EXPECT_EQ(t[1].index, 3);
}

// ---- Paths through scenes built in code, every pdf from the real Bsdf / Light ----

#include "tests/support/mis_scene_path.h"

namespace {

std::vector<Material> testMaterials() {
    std::vector<Material> m(6);
    m[0].name = "diffuse";
    m[0].diffuse = Rgb(0.7f, 0.5f, 0.3f);
    m[1].name = "glossy phong";
    m[1].type = MaterialType::Phong;
    m[1].diffuse = Rgb(0.2f);
    m[1].glossy = Rgb(0.6f);
    m[1].exponent = 30;
    m[2].name = "mirror";
    m[2].type = MaterialType::Mirror;
    m[3].name = "glass";
    m[3].type = MaterialType::Dielectric;
    m[3].ior = 1.5f;
    m[4].name = "rough conductor";
    m[4].type = MaterialType::RoughConductor;
    m[4].alpha = 0.3f;
    m[5].name = "rough glass";
    m[5].type = MaterialType::RoughDielectric;
    m[5].alpha = 0.3f;
    m[5].ior = 1.5f;
    return m;
}

Light quadLight() {
    Light l;
    l.type = LightType::Area;
    l.name = "quad";
    l.radiance = Rgb(5.0f);
    Vec3 a(-0.5f, -0.5f, 0), b(0.5f, -0.5f, 0), c(0.5f, 0.5f, 0), d(-0.5f, 0.5f, 0);
    l.triangles = {a, b, c, a, c, d};  // emits towards +z
    l.prepare();
    return l;
}

Light pointLight() {
    Light l;
    l.type = LightType::Point;
    l.name = "point";
    l.intensity = Rgb(3.0f);
    l.position = Vec3(0, 0, 0);
    l.prepare();
    return l;
}

}  // namespace

TEST(MisBruteForce, ScenePathsWithRealBsdfsMatchExplicitPdfWeights) {
    const std::vector<Material> materials = testMaterials();
    const Light lights[2] = {quadLight(), pointLight()};
    const MisLightKind kinds[2] = {MisLightKind::Area, MisLightKind::Point};
    SceneSphere sphere;
    sphere.radius = 5.0f;
    sphere.invRadiusSqr = 1.0f / 25.0f;
    Rng rng(2024, 3);
    int paths = 0, compared = 0, attempts = 0;
    for (const NamedConfig& nc : configs()) {
        for (int n = 0; n < 600; ++n) {
            int li = n % 2;
            int k = 2 + int(rng.uniform() * 6);
            MisPath p;
            std::string problem;
            bool ok = false;
            for (int tries = 0; tries < 200 && !ok; ++tries, ++attempts) {
                ok = sampleScenePath(rng, lights[li], kinds[li], 0.5f, sphere, materials, k, &p,
                                     &problem);
                ASSERT_TRUE(problem.empty()) << problem;
            }
            ASSERT_TRUE(ok) << "could not sample a path of length " << k;
            ++paths;
            auto ref = bruteForceWeights(p, nc.cfg);
            auto rec = recursiveWeights(p, nc.cfg);
            ASSERT_EQ(ref.size(), rec.size());
            double sum = 0;
            for (size_t t = 0; t < ref.size(); ++t) {
                ASSERT_NEAR(rec[t].weight, ref[t].weight, 1e-4)
                    << nc.name << " " << lights[li].name << " k=" << k << " technique "
                    << ref[t].name();
                sum += rec[t].weight;
                ++compared;
            }
            if (!rec.empty()) ASSERT_NEAR(sum, 1.0, 1e-4) << nc.name << " k=" << k;
        }
    }
    EXPECT_EQ(paths, 6 * 600);
    EXPECT_GT(compared, 5000);
}
