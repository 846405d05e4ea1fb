// BeamMedium (see beam_medium.h).
#include "estimators/beam_medium.h"

#include <algorithm>
#include <cmath>

#include "estimators/grid_access.h"
#include "estimators/volume_estimate.h"
#include "scene/medium.h"
#include "scene/scene.h"

namespace ub {

std::vector<BeamMediumPrep> prepareBeamMedia(const Scene& scene) {
    std::vector<BeamMediumPrep> prep(scene.media.size());
    for (size_t i = 0; i < prep.size(); ++i) {
        const Medium& m = scene.media[i];
        BeamMediumPrep& p = prep[i];
        p.medium = &m;
        // The table is grey (one extinction per piece): chromatic grids evaluate per pair.
        p.tabulated =
            m.type == MediumType::kGrid && m.filter != GridFilter::kTrilinear && !m.chromatic();
        p.info = mediumInfo(m);
        p.contProb = ub_homogeneous_cont_prob(p.info);
    }
    return prep;
}

ub_grid_info gridInfo(const Medium& m, uint32_t gridOffset) {
    ub_grid_info g{};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) g.worldToCell[4 * r + c] = m.worldToCell.m[r][c];
    g.densityScale = m.densityScale;
    g.background = m.grid->background();
    for (int a = 0; a < 3; ++a) g.albedo[a] = m.albedo[a];
    g.g = m.g;
    const nanovdb::CoordBBox& bb = m.grid->indexBounds();
    for (int a = 0; a < 3; ++a) {
        g.lo[a] = bb.min()[a];
        g.hi[a] = bb.max()[a] + 1;
    }
    g.gridOffset = gridOffset;
    return g;
}

ub_medium_info mediumInfo(const Medium& m) {
    ub_medium_info info{};
    const Rgb st = m.sigmaA + m.sigmaS;
    for (int a = 0; a < 3; ++a) {
        info.sigmaT[a] = st[a];
        info.sigmaS[a] = m.sigmaS[a];
    }
    info.g = m.g;
    info.homogeneous = m.type == MediumType::kHomogeneous ? 1u : 0u;
    return info;
}

void BeamMedium::build() {
    built_ = true;
    if (!tabulated_ || !(beam_->length > 0.0f)) return;
    const ub_grid_info g = gridInfo(*medium_, 0);
    ub_grid_accessor acc{medium_->grid->grid().getAccessor()};
    const ub_float3 o = ub_f3_from(beam_->origin), d = ub_f3_from(beam_->dir);
    // The walk fills what fits and counts the rest: one more walk when 64 were too few.
    pieces_.resize(64);
    for (;;) {
        float sFirst = 0.0f, sLast = 0.0f;
        ub_uint n = 0;
        ub_grid_walk(g, &acc, o, d, beam_->length, beam_->length, &sFirst, &sLast, pieces_.data(),
                     ub_uint(pieces_.size()), &n);
        const bool fits = n <= pieces_.size();
        pieces_.resize(n);
        if (fits) break;
    }
}

ub_segment_eval BeamMedium::evalOther(float t) const {
    const Vec3 o(beam_->origin[0], beam_->origin[1], beam_->origin[2]);
    const Vec3 d(beam_->dir[0], beam_->dir[1], beam_->dir[2]);
    if (!tabulated_ || pieces_.empty()) {
        const MediumSegment s = evalMediumSegment(*medium_, o, d, t);
        ub_segment_eval e;
        for (int a = 0; a < 3; ++a) {
            e.transmittance[a] = s.transmittance[a];
            e.sigmaS[a] = s.sigmaS1[a];
        }
        e.stopFwdL = s.pdfScatterFwdL();
        e.stopRevStartL = s.pdfScatterRevL();
        e.passProb = s.probPass();
        e.contProb = ub_medium_cont_prob(s.sigmaS1[0], s.sigmaS1[1], s.sigmaS1[2], s.sigmaT1[0],
                                         s.sigmaT1[1], s.sigmaT1[2]);
        return e;
    }
    float sFirst = 0.0f, sLast = 0.0f;
    const float tau =
        ub_beam_table_tau_g(pieces_.data(), ub_uint(pieces_.size()), t, &sFirst, &sLast);
    // The albedo at the point: constant, or from the medium's albedo grid.
    const Rgb albedo = mediumAlbedoAt(*medium_, o + d * t);
    return ub_grey_segment(tau, sFirst, sLast, albedo[0], albedo[1], albedo[2]);
}

void flattenBeamTables(const std::vector<BeamMedium>& media, std::vector<ub_beam_piece>* pieces,
                       std::vector<uint32_t>* ranges) {
    pieces->clear();
    ranges->assign(2 * media.size(), 0u);
    for (size_t b = 0; b < media.size(); ++b) {
        const std::vector<ub_beam_piece>& p = media[b].pieces();
        (*ranges)[2 * b] = uint32_t(pieces->size());
        (*ranges)[2 * b + 1] = uint32_t(p.size());
        pieces->insert(pieces->end(), p.begin(), p.end());
    }
}

}  // namespace ub
