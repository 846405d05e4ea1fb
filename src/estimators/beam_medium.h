// The medium along one beam, evaluated at many parameters t: what the beam
// estimators need at each photon-query pair (estimators/volume_estimate.h).
//
// In a grid medium (nearest filtering) the extinction is constant on the pieces
// regular tracking visits, so the optical depth along the beam is piecewise
// linear in t: one walk over the whole beam (the kernels' DDA, ub_grid_walk)
// gives a table of pieces (kernels/shared/ub_beam_table.h), and every later
// evaluation is a binary search plus an exponential -- the same values as a walk
// from the beam start to t (scene/medium.h evalMediumSegment), up to the rounding
// of the sum, at O(log pieces) instead of O(voxels). The beam kernels read the
// photon beams' tables (flattenBeamTables) and build the query beams' own.
// Homogeneous media use their closed form, trilinear and chromatic grids
// evalMediumSegment.
#pragma once

#include <vector>

#include "kernels/shared/ub_beam_table.h"
#include "kernels/shared/ub_medium_homogeneous.h"
#include "kernels/shared/ub_upbp_records.h"

namespace ub {

class Scene;
struct Medium;

/// What BeamMedium needs of a medium, the same for every beam in it: prepared once per pass
/// (prepareBeamMedia) rather than per query beam. Derived per query, it was 4% of bb1d's host
/// pass on the bunny (docs/performance.md, session 46).
struct BeamMediumPrep {
    const Medium* medium = nullptr;
    ub_medium_info info{};
    float contProb = 0.0f;  ///< ub_homogeneous_cont_prob(info)
    bool tabulated = false;
};

/// One BeamMediumPrep per medium of the scene, indexed by medium id.
std::vector<BeamMediumPrep> prepareBeamMedia(const Scene& scene);

class BeamMedium {
  public:
    /// Prepares for beam b in its medium (prep: prepareBeamMedia's entry for b.mediumId);
    /// build() must follow before eval (query loops call it when they find the beam's first
    /// pair, so beams without pairs cost nothing).
    void reset(const BeamMediumPrep& prep, const ub_beam& b) {
        medium_ = prep.medium;
        beam_ = &b;
        tabulated_ = prep.tabulated;
        built_ = false;
        pieces_.clear();
        info_ = prep.info;
        contProb_ = prep.contProb;
    }
    void build();
    bool built() const { return built_; }
    /// The medium from the beam's piece start to distance t in [0, b.length] (after build()).
    /// Homogeneous media inline, with their continuation probability computed once: the
    /// closed form was 16% of bb1d's host pass on mirrorballs as a call (perf).
    ub_segment_eval eval(float t) const {
        return info_.homogeneous ? ub_homogeneous_segment_cp(info_, t, contProb_) : evalOther(t);
    }
    size_t bytes() const { return pieces_.capacity() * sizeof(ub_beam_piece); }
    /// The table (empty: homogeneous or trilinear medium, or a beam of no length).
    const std::vector<ub_beam_piece>& pieces() const { return pieces_; }

  private:
    const Medium* medium_ = nullptr;
    const ub_beam* beam_ = nullptr;
    ub_segment_eval evalOther(float t) const;
    bool tabulated_ = false, built_ = false;
    float contProb_ = 0.0f;  ///< homogeneous media: ub_homogeneous_cont_prob(info_)
    std::vector<ub_beam_piece> pieces_;
    ub_medium_info info_{};  ///< homogeneous media: the closed form of the kernels
};

/// The photon beams' tables for the beam kernels: the pieces of beam b are
/// pieces[ranges[2 b]], ... (ranges[2 b + 1] of them; 0: none, the kernel walks).
void flattenBeamTables(const std::vector<BeamMedium>& media, std::vector<ub_beam_piece>* pieces,
                       std::vector<uint32_t>* ranges);

/// What the kernels know of a medium (kernels/shared/ub_medium_homogeneous.h).
ub_medium_info mediumInfo(const Medium& m);

}  // namespace ub
