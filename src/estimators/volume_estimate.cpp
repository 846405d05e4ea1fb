// The UPBP estimate pass: lookups and the order of accumulation (see
// volume_estimate.h). The estimators themselves are in *_estimator.cpp.
#include "estimators/volume_estimate.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cl/cl_runtime.h"
#include "core/memory_budget.h"
#include "core/seconds.h"
#include "estimators/beam_medium.h"
#include "estimators/bvh.h"
#include "estimators/grid_access.h"
#include "estimators/hash_grid.h"
#include "kernels/shared/ub_bb1d.h"
#include "kernels/shared/ub_bp2d.h"
#include "kernels/shared/ub_pb2d.h"
#include "kernels/shared/ub_pp3d.h"
#include "scene/medium.h"
#include "scene/scene.h"

namespace ub {

namespace {

/// Box of the cylinder of radius r around o + t d, t in [t0, t1].
Bounds3 cylinderBox(const Vec3& o, const Vec3& d, float t0, float t1, float r) {
    Bounds3 b;
    const Vec3 pad(r, r, r);
    b.extend(o + d * t0 - pad);
    b.extend(o + d * t0 + pad);
    b.extend(o + d * t1 - pad);
    b.extend(o + d * t1 + pad);
    return b;
}

Vec3 vec(const float v[3]) {
    return Vec3(v[0], v[1], v[2]);
}

}  // namespace

void estimateVolume(const VolumeEstimateInput& in, Image* image, std::array<Image, 4>* layers,
                    VolumeEstimateStats* stats) {
    VolumeEstimateStats local;
    VolumeEstimateStats& st = stats ? *stats : local;
    for (uint64_t& n : st.rejected) n = 0;
    st = VolumeEstimateStats();
    const UpbpTechniques& t = in.techniques;
    const std::vector<ub_photon_point>& photons = *in.photonPoints;
    const std::vector<ub_beam>& beams = *in.photonBeams;
    const size_t nPoints = in.queryPoints->size(), nBeams = in.queryBeams->size();

    auto t0 = std::chrono::steady_clock::now();
    // Lookups reserve their memory in the budget before they are built (freed at the end).
    const char* kLookupAdvice =
        "a smaller --resolution, fewer --beam-paths or a smaller --max-length need less";
    std::vector<std::unique_ptr<MemoryReservation>> reservations;
    auto reserve = [&](size_t bytes, const char* what) {
        reservations.push_back(
            std::make_unique<MemoryReservation>(in.budget, bytes, what, kLookupAdvice));
    };
    HashGrid grid;
    if (t.pp3d && !photons.empty()) {
        // Cell ends (one per photon at least) and indices.
        reserve(photons.size() * 3 * sizeof(uint32_t) + 64, "pp3d lookup (hashed grid)");
        grid.build(reinterpret_cast<const Vec3*>(photons.data()->pos), photons.size(),
                   sizeof(ub_photon_point), in.radius[UB_TECH_PP3D]);
    }
    Bvh spheres;
    std::vector<ub_photon_point> sphereOrder;
    std::vector<ub_photon_keys4> sphereKeys;
    ScreenTiles photonTiles;
    if (t.pb2d) {
        // Boxes, nodes (at most 2 n / leaf size + 1) and the primitive list.
        reserve(photons.size() * (sizeof(Bounds3) + sizeof(Vec3) + 4 + Bvh::kNodeBytesPerBox),
                "pb2d lookup (photon-point BVH)");
        const float r = in.radius[UB_TECH_PB2D];
        std::vector<Bounds3> boxes(photons.size());
        for (size_t i = 0; i < photons.size(); ++i) {
            const Vec3 p = vec(photons[i].pos);
            boxes[i].extend(p - Vec3(r, r, r));
            boxes[i].extend(p + Vec3(r, r, r));
        }
        // Leaves of up to 12 photons, tested four at a time (ub_photon_keys4): against 4, the
        // pb2d estimate pass 8-11% faster on the bunny and cornell-fog, host and kernel, and the
        // BVH builds faster (docs/performance.md).
        // One tree per medium (Bvh::build's groups): a query walks its medium's photons only.
        std::vector<uint32_t> media(photons.size());
        for (size_t i = 0; i < photons.size(); ++i) media[i] = photons[i].mediumId;
        spheres.build(boxes, 12, Bvh::kStackSize, mediumTreesAllowed() ? &media : nullptr);
        // A copy of the photons in leaf order, read one after the other by the walks.
        reserve(photons.size() * sizeof(ub_photon_point), "pb2d lookup (photons in leaf order)");
        sphereOrder = photons;
        spheres.permuteToLeafOrder(&sphereOrder);
        // What the walks test first, 16 bytes a photon, four photons a block
        // (kernels/shared/ub_pb2d.h).
        reserve((photons.size() / 4 + 1) * sizeof(ub_photon_keys4), "pb2d lookup (photon keys)");
        sphereKeys.assign((sphereOrder.size() + 3) / 4, ub_photon_keys4{});
        for (ub_photon_keys4& k : sphereKeys)
            for (int j = 0; j < 4; ++j) k.mediumId[j] = UB_NO_MEDIUM;
        for (size_t i = 0; i < sphereOrder.size(); ++i)
            ub_photon_keys4_set(&sphereKeys[i / 4], int(i % 4), sphereOrder[i]);
        // The photons by screen tile, for the query beams through the camera's eye.
        buildPhotonScreenTiles(
            in.scene->camera, in.scene->sceneSphere.radius, sphereOrder, r,
            [&](size_t bytes) { reserve(bytes, "pb2d lookup (screen tiles)"); }, &photonTiles);
        st.photonScreenTiles = photonTiles.params;
    }
    Bvh beamBvh;
    std::vector<BeamPart> parts;
    std::vector<ub_beam_keys4> partLines;
    ScreenTiles tiles;
    if (t.photonBeams()) {
        const float r = std::max(t.bp2d ? in.radius[UB_TECH_BP2D] : 0.0f,
                                 t.bb1d ? in.radius[UB_TECH_BB1D] : 0.0f);
        // Parts of at least 32 r, at most 32 per beam: measured (bb1d on mirrorballs, bunny,
        // cornell-fog at 256x256, docs/performance.md) against 4 r / 64 (1.3-2x slower), 16 r /
        // 16 and 2 r / 64: since the candidates' data sit in the parts in leaf order, a
        // candidate costs little next to a node visit, and coarser parts mean fewer nodes.
        auto partCount = [&](const ub_beam& b) {
            return int(std::min(32.0f, std::max(1.0f, std::ceil(b.length / (32.0f * r)))));
        };
        size_t total = 0;
        for (const ub_beam& b : beams) total += size_t(partCount(b));
        reserve(
            total * (sizeof(BeamPart) + sizeof(Bounds3) + sizeof(Vec3) + 4 + Bvh::kNodeBytesPerBox),
            "bp2d/bb1d lookup (beam-part BVH)");
        std::vector<Bounds3> boxes;
        parts.reserve(total);
        boxes.reserve(total);
        for (uint32_t i = 0; i < beams.size(); ++i) {
            const ub_beam& b = beams[i];
            const int n = partCount(b);
            for (int k = 0; k < n; ++k) {
                const float a = b.length * float(k) / float(n);
                const float e = k + 1 == n ? b.length : b.length * float(k + 1) / float(n);
                parts.push_back(ub_beam_part_of(b, i, a, e));
                boxes.push_back(cylinderBox(vec(b.origin), vec(b.dir), a, e, r));
            }
        }
        // Leaves of up to 12 parts: bb1d tests a leaf's lines four at a time (ub_beam_keys4),
        // which makes a candidate cheaper than a node; against 8, bb1d's estimate pass 5-12%
        // faster on cornell-fog and mirrorballs, bp2d within noise (docs/performance.md).
        // One tree per medium (Bvh::build's groups): a query walks its medium's parts only.
        std::vector<uint32_t> media(parts.size());
        for (size_t i = 0; i < parts.size(); ++i) media[i] = parts[i].mediumId;
        beamBvh.build(boxes, 12, Bvh::kStackSize, mediumTreesAllowed() ? &media : nullptr);
        // The parts in leaf order, so that a walk reads its candidates one after the other.
        beamBvh.permuteToLeafOrder(&parts);
        if (t.bb1d) {
            // What the bb1d walks test first, four parts a block (kernels/shared/ub_bvh.h).
            reserve((parts.size() / 4 + 1) * sizeof(ub_beam_keys4), "bb1d lookup (part lines)");
            partLines.assign((parts.size() + 3) / 4, ub_beam_keys4{});
            for (size_t i = 0; i < parts.size(); ++i)
                ub_beam_keys4_set(&partLines[i / 4], int(i % 4), parts[i]);
            // The parts by screen tile, for the query beams through the camera's eye.
            buildScreenTiles(
                in.scene->camera, in.scene->sceneSphere.radius, beams, parts, r,
                [&](size_t bytes) { reserve(bytes, "bb1d lookup (screen tiles)"); }, &tiles);
            st.screenTiles = tiles.params;
        }
    }
    // The medium along every photon beam, tabulated once (estimators/beam_medium.h).
    std::vector<BeamMedium> photonMedia(t.photonBeams() ? beams.size() : 0);
    const std::vector<BeamMediumPrep> beamMedia = prepareBeamMedia(*in.scene);
    tbb::parallel_for(size_t(0), photonMedia.size(), [&](size_t i) {
        photonMedia[i].reset(beamMedia[beams[i].mediumId], beams[i]);
        photonMedia[i].build();
    });
    // The beam kernels read the tables flattened (empty in homogeneous media).
    std::vector<ub_beam_piece> beamPieces;
    std::vector<uint32_t> beamRanges;
    if (in.beamKernels && in.cl && (t.bp2d || t.bb1d))
        flattenBeamTables(photonMedia, &beamPieces, &beamRanges);
    size_t mediaBytes = photonMedia.size() * sizeof(BeamMedium) +
                        beamPieces.size() * sizeof(ub_beam_piece) +
                        beamRanges.size() * sizeof(uint32_t);
    for (const BeamMedium& m : photonMedia) mediaBytes += m.bytes();
    // Tabulated after the walk (its size is known only then): at most this one structure
    // goes over the budget before the render stops.
    reserve(mediaBytes, "photon-beam medium tables");
    st.lookupBytes += mediaBytes;
    st.buildSeconds = secondsSince(t0);
    st.lookupBytes += spheres.bytes() + sphereOrder.size() * sizeof(ub_photon_point) +
                      sphereKeys.size() * sizeof(ub_photon_keys4) + beamBvh.bytes() +
                      parts.size() * sizeof(BeamPart) + partLines.size() * sizeof(ub_beam_keys4) +
                      tiles.bytes() + photonTiles.bytes();

    t0 = std::chrono::steady_clock::now();
    std::vector<Rgb> perPoint[4], perBeam[4];
    // The media as the kernels see them and the grid media on the device were prepared once
    // for the render (prepareDeviceMedia).
    static const std::vector<ub_medium_info> kNoMedia(1, ub_medium_info{});
    const std::vector<ub_medium_info>& media = in.deviceMedia ? *in.deviceMedia : kNoMedia;
    ClRuntime* beamCl = in.beamKernels ? in.cl : nullptr;
    auto clArgs = [&](int tech, float normalization) {
        ClRuntime::EstimateArgs a;
        a.media = &media;  // grids: resident on the device (ClRuntime::setGridMedia)
        a.mis = in.mis;
        a.radius = in.radius[tech];
        a.normalization = normalization;
        a.minLength = uint32_t(in.minLength);
        a.maxLength = uint32_t(in.maxLength);
        return a;
    };
    if (t.pp3d) {
        perPoint[UB_TECH_PP3D].assign(nPoints, Rgb(0.0f));
        if (in.cl) {
            in.cl->estimatePP3D(
                photons, grid, *in.queryPoints,
                clArgs(UB_TECH_PP3D,
                       ub_pp3d_normalization(in.lightPathCount, in.radius[UB_TECH_PP3D])),
                &perPoint[UB_TECH_PP3D]);
            st.pairs[UB_TECH_PP3D] = VolumeEstimateStats::kNotCounted;
        } else {
            estimatePP3D(in, grid, &perPoint[UB_TECH_PP3D], &st.pairs[UB_TECH_PP3D]);
        }
    }
    if (t.bp2d) {
        perPoint[UB_TECH_BP2D].assign(nPoints, Rgb(0.0f));
        const float r = in.radius[UB_TECH_BP2D];
        if (beamCl) {
            beamCl->estimateBP2D(beams, parts, beamPieces, beamRanges, beamBvh, *in.queryPoints,
                                 clArgs(UB_TECH_BP2D, ub_bp2d_normalization(in.beamPathCount, r)),
                                 &perPoint[UB_TECH_BP2D]);
            st.pairs[UB_TECH_BP2D] = VolumeEstimateStats::kNotCounted;
        } else {
            estimateBP2D(in, beamBvh, parts, photonMedia, &perPoint[UB_TECH_BP2D],
                         &st.pairs[UB_TECH_BP2D]);
        }
    }
    if (t.pb2d) {
        perBeam[UB_TECH_PB2D].assign(nBeams, Rgb(0.0f));
        const float r = in.radius[UB_TECH_PB2D];
        if (beamCl) {
            beamCl->estimatePB2D(sphereOrder, sphereKeys, spheres, photonTiles, *in.queryBeams,
                                 clArgs(UB_TECH_PB2D, ub_pb2d_normalization(in.lightPathCount, r)),
                                 &perBeam[UB_TECH_PB2D]);
            st.pairs[UB_TECH_PB2D] = VolumeEstimateStats::kNotCounted;
        } else {
            estimatePB2D(in, spheres, sphereOrder, sphereKeys, photonTiles, &perBeam[UB_TECH_PB2D],
                         &st.pairs[UB_TECH_PB2D]);
        }
    }
    if (t.bb1d) {
        perBeam[UB_TECH_BB1D].assign(nBeams, Rgb(0.0f));
        const float r = in.radius[UB_TECH_BB1D];
        if (beamCl) {
            beamCl->estimateBB1D(beams, parts, partLines, beamPieces, beamRanges, beamBvh, tiles,
                                 *in.queryBeams,
                                 clArgs(UB_TECH_BB1D, ub_bb1d_normalization(in.beamPathCount, r)),
                                 &perBeam[UB_TECH_BB1D]);
            st.pairs[UB_TECH_BB1D] = VolumeEstimateStats::kNotCounted;
        } else {
            estimateBB1D(in, beamBvh, parts, partLines, photonMedia, tiles, &perBeam[UB_TECH_BB1D],
                         &st.pairs[UB_TECH_BB1D]);
        }
    }
    st.estimateSeconds = secondsSince(t0);

    // Accumulate in query order (deterministic), each estimate through its technique's guard.
    const int width = image->width;
    auto add = [&](uint32_t pixel, int tech, Rgb v) {
        if (!in.guards[tech].filter(pixel, &v, &st.rejected[tech])) return;
        const int x = int(pixel % uint32_t(width)), y = int(pixel / uint32_t(width));
        image->at(x, y) += v;
        if (layers) (*layers)[size_t(tech)].at(x, y) += v;
    };
    for (int tech = 0; tech < 4; ++tech) {
        if (!perPoint[tech].empty())
            for (size_t i = 0; i < nPoints; ++i)
                add((*in.queryPoints)[i].pixel, tech, perPoint[tech][i]);
        if (!perBeam[tech].empty())
            for (size_t i = 0; i < nBeams; ++i)
                add((*in.queryBeams)[i].pixel, tech, perBeam[tech][i]);
    }
}

bool prepareDeviceMedia(const Scene& scene, ClRuntime* cl, bool needGrids,
                        std::vector<ub_medium_info>* media) {
    // The beam kernels evaluate homogeneous media in closed form and nearest-filtered grids
    // without an albedo grid by regular tracking through the grid (kernels/beams.cl); the
    // grids go to the device concatenated, each at a 32-byte aligned offset (NanoVDB's
    // alignment), once per render. Other grid media keep the beam estimators on the host.
    media->clear();
    std::vector<ub_grid_info> grids(scene.media.size());
    std::vector<uint8_t> gridData;
    bool beamKernels = true;
    for (size_t i = 0; i < scene.media.size(); ++i) {
        const Medium& m = scene.media[i];
        media->push_back(mediumInfo(m));
        if (m.type == MediumType::kHomogeneous || !needGrids) continue;
        if (!gridMediumOnDevice(m)) {
            beamKernels = false;
            continue;
        }
        const size_t offset = (gridData.size() + 31) & ~size_t(31);
        const nanovdb::FloatGrid& g = m.grid->grid();
        const uint8_t* bytes = reinterpret_cast<const uint8_t*>(&g);
        gridData.resize(offset);
        gridData.insert(gridData.end(), bytes, bytes + g.gridSize());
        grids[i] = gridInfo(m, uint32_t(offset));
    }
    if (media->empty()) media->push_back(ub_medium_info{});  // never an empty buffer
    if (cl && beamKernels) cl->setGridMedia(grids, gridData);
    return beamKernels;
}

}  // namespace ub
