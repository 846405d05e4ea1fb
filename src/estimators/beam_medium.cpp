// BeamMedium (see beam_medium.h).
#include "estimators/beam_medium.h"

#include <algorithm>
#include <cmath>

#include "estimators/grid_access.h"
#include "estimators/volume_estimate.h"
#include "scene/medium.h"
#include "scene/scene.h"

namespace ub {

void BeamMedium::reset(const Scene& scene, const ub_beam& b) {
    medium_ = &scene.media[b.mediumId];
    beam_ = &b;
    tabulated_ = medium_->type == MediumType::kGrid && medium_->filter != GridFilter::kTrilinear;
    built_ = false;
    pieces_.clear();
    info_ = mediumInfo(*medium_);
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
    if (!tabulated_) return;
    const Vec3 o(beam_->origin[0], beam_->origin[1], beam_->origin[2]);
    const Vec3 d(beam_->dir[0], beam_->dir[1], beam_->dir[2]);
    float tau = 0.0f;
    gridPieces(*medium_, o, d, beam_->length, [&](float ta, float tb, float sigmaT) {
        pieces_.push_back({ta, sigmaT, tau});
        tau += sigmaT * (tb - ta);
    });
}

ub_segment_eval BeamMedium::eval(float t) const {
    const Vec3 o(beam_->origin[0], beam_->origin[1], beam_->origin[2]);
    const Vec3 d(beam_->dir[0], beam_->dir[1], beam_->dir[2]);
    if (medium_->type == MediumType::kHomogeneous) return ub_homogeneous_segment(info_, t);
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
    // The piece holding t: the last one starting at or before t (a t on a piece boundary
    // belongs to the piece it starts, as in the walk, whose last piece ends at t).
    auto it = std::upper_bound(pieces_.begin(), pieces_.end(), t,
                               [](float x, const Piece& p) { return x < p.t0; });
    const Piece& p = it == pieces_.begin() ? pieces_.front() : *(it - 1);
    // The walk to t ends in the piece before a boundary at exactly t.
    const Piece& last =
        (it != pieces_.begin() && p.t0 == t && it - 1 != pieces_.begin()) ? *(it - 2) : p;
    const float tau = last.tau0 + last.sigmaT * (t - last.t0);
    const float T = std::exp(-tau);
    const float sigmaT0 = pieces_.front().sigmaT, sigmaT1 = last.sigmaT;
    const Rgb albedo = mediumAlbedoAt(*medium_, o + d * t);
    ub_segment_eval e;
    for (int a = 0; a < 3; ++a) {
        e.transmittance[a] = T;
        e.sigmaS[a] = albedo[a] * sigmaT1;
    }
    e.stopFwdL = sigmaT1 * T;
    e.stopRevStartL = sigmaT0 * T;
    e.passProb = T;
    e.contProb =
        ub_medium_cont_prob(e.sigmaS[0], e.sigmaS[1], e.sigmaS[2], sigmaT1, sigmaT1, sigmaT1);
    return e;
}

}  // namespace ub
