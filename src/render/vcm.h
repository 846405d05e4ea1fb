// The surface bidirectional family in one engine, with SmallVCM's algorithm
// names (Georgiev et al. 2012, "Light Transport Simulation with Vertex
// Connection and Merging"; tech. report "Implementing Vertex Connection and
// Merging", cited as [TR (n)]):
//
//   lt   light tracing: light subpaths connected to the camera (no MIS)
//   bpt  bidirectional path tracing: camera hits, NEE, vertex connections and
//        light tracing, combined by MIS
//   ppm  progressive photon mapping (Hachisuka et al. 2008): merging at the first
//        non-specular camera vertex, no MIS
//   bpm  bidirectional photon mapping (Vorba 2011): merging at every non-specular
//        camera vertex, combined by MIS
//   vcm  vertex connection and merging: all of bpt plus bpm, combined by MIS
//
// One iteration (DESIGN.md): (1) one light subpath per pixel, its non-specular
// vertices stored as LightVertex with MIS partials (render/light_vertex.h),
// light-tracing splats recorded in a deterministic SplatBuffer; (2) a hashed grid
// over the light vertices (merging algorithms); (3) one camera subpath per
// pixel, paired with the light subpath of the same index for connections.
// The MIS math is kernels/shared/ub_mis.h.
//
// Merging radius of iteration i (1-based): r_i = r_1 i^((alpha-1)/2) (Knaus &
// Zwicker 2011; TR Sec. 4), r_1 = RenderOptions::radius, times the scene
// bounding-sphere radius if radiusIsRelative.
//
// Media (`vlt`, `vbpt`: light tracing and bidirectional path tracing with
// participating media; Lafortune & Willems 1996, "Rendering Participating Media
// with Bidirectional Path Tracing"; MIS as in Krivanek et al. 2014, UPBP, for the
// connection techniques): when the algorithm is vlt or vbpt and the scene has
// media, both subpaths trace segment chains through imaginary and skipped
// boundaries (Scene::traceMedia) and sample free-flight distances along them
// (render/medium_walk.h), so they also scatter at medium vertices with the HG
// phase function (render/vertex_scatter.h). Medium vertices are stored as light
// vertices (UB_LIGHT_VERTEX_IN_MEDIUM), connected to the camera, to camera
// vertices and to lights like surface vertices, with the transmittance of the
// connecting chain (Scene::shadowTransmittance, through imaginary boundaries).
// Every MIS pdf includes the free-flight pdfs of its segment in its direction
// (kernels/shared/ub_mis.h, MEDIA). Emission of a medium (sigma_a Le) is added by
// the camera subpath of vbpt at its medium vertices with the collision estimator
// and weight 1 (no other technique samples it, as in `vpt`); vlt rejects scenes
// with emitting media. Lights at infinity cannot start subpaths inside a global
// medium (the medium would have to extend to infinity): vlt and vbpt reject such
// scenes. Without media vlt and vbpt are lt and bpt.
//
// Conventions shared with `pt` (render/pt.h): path length counts segments, a
// light seen directly has length 1 (with DepthCounting::kNonNullVertices, Mitsuba
// scenes, a vertex whose sampled lobe continues the ray unchanged, a thin sheet's
// transmission, ends no segment: the lengths of both subpaths and of connections
// count the other vertices only; such a vertex stays a delta vertex for MIS, never
// connected to); surfaces that emit and have a material keep
// scattering; Russian roulette with Bsdf::continuationProb(). Light tracing
// connects to every camera: a pinhole, a thin lens (a sampled lens point) and the
// orthographic film (estimators/light_tracing.cpp).
#pragma once

#include <memory>
#include <vector>

#include "core/memory_budget.h"
#include "estimators/hash_grid.h"
#include "kernels/shared/ub_medium_homogeneous.h"
#include "kernels/shared/ub_mis_volume.h"
#include "kernels/shared/ub_surf.h"
#include "kernels/shared/ub_upbp_records.h"
#include "render/film.h"
#include "render/integrator.h"
#include "render/light_vertex.h"
#include "render/upbp_techniques.h"
#include "scene/bsdf.h"
#include "scene/medium_stack.h"

namespace ub {

class Rng;
class ClRuntime;
class VertexScatter;
class LightScatterCache;
struct VolumeEstimateInput;
struct ChainVertex;

class VertexCM : public Integrator {
  public:
    enum class Algorithm { LightTrace, Bpt, Ppm, Bpm, Vcm, Upbp };

    /// Reads options.algorithm (lt, bpt, ppm, bpm, vcm, vlt, vbpt). Throws InputError for
    /// another name, a thin-lens camera with lt/bpt/vcm/vlt/vbpt, a bad radius/alpha, or a
    /// media set-up vlt/vbpt cannot render (see above).
    VertexCM(const Scene& scene, const RenderOptions& options);
    ~VertexCM() override;
    void renderIteration(int iteration, Image& out) override;
    /// UPBP: one layer per technique run ("bpt", or "emitted" without bpt: what the camera
    /// pass adds besides merging; "surf", "pp3d", "pb2d", "bp2d", "bb1d").
    std::vector<std::string> layerNames() const override { return layerNames_; }
    const std::vector<Image>* iterationLayers() const override {
        return layerNames_.empty() ? nullptr : &layers_;
    }
    std::string iterationSummary() const override;
    /// Techniques: UPBP's layer names, else the algorithm (render/contribution_guard.h).
    RejectionCounts rejectedContributions() const override;
    /// Where the estimate pass runs, in words (UPBP; empty otherwise).
    std::string setupNote() const override { return backendNote_; }

    /// What replayEstimate measured, in seconds: building the lookups (host, both backends)
    /// and the estimates themselves; and how many queries the estimator evaluated.
    struct EstimateTiming {
        double lookups = 0, estimates = 0;
        size_t queries = 0;
        /// On the device with RenderOptions::clProfile: the kernel's time on the device and
        /// its latency from submission to start (ClRuntime::lastKernelTiming); else -1.
        double deviceKernel = -1, deviceStartLatency = -1;
    };
    /// UPBP: runs the last iteration's estimate pass again for one technique ("surf", "pp3d",
    /// "pb2d", "bp2d" or "bb1d", which the render must run) over the same photons, beams and
    /// queries, with its OpenCL kernel (onDevice; the render must have one) or its host twin,
    /// adding the estimates to `out` (width x height). For bench_upbp --replay, which times
    /// the two backends alternately on the same buffers. Throws std::invalid_argument for
    /// another technique.
    EstimateTiming replayEstimate(const std::string& technique, bool onDevice, Image* out);
    /// True if the estimate pass can run on an OpenCL device (replayEstimate's onDevice).
    bool hasDeviceEstimates() const { return cl_ != nullptr; }

    Algorithm algorithm() const { return algorithm_; }
    /// True if subpaths are traced through participating media (vlt/vbpt on a scene with
    /// media).
    bool tracesMedia() const { return useMedia_; }
    /// Merging radius used by iteration `iteration` (0-based).
    float radiusAt(int iteration) const;
    /// Light vertices stored by the last iteration (for tests).
    const std::vector<LightVertex>& lightVertices() const { return lightVertices_; }
    /// UPBP: the techniques run (all false for the other algorithms).
    const UpbpTechniques& upbpTechniques() const { return upbp_; }
    /// UPBP records of the last iteration (for tests and the summary).
    const std::vector<ub_photon_point>& photonPoints() const { return photonPoints_; }
    const std::vector<ub_beam>& photonBeams() const { return photonBeams_; }
    const std::vector<ub_query_point>& queryPoints() const { return queryPoints_; }
    const std::vector<ub_beam>& queryBeams() const { return queryBeams_; }
    /// UPBP: radius of a volumetric technique (UB_TECH_*) in iteration `iteration` (0-based).
    float volumeRadiusAt(int tech, int iteration) const;
    /// Light subpaths per iteration that emit photon beams.
    int beamPathCount() const { return beamPaths_; }

  private:
    /// State of a subpath being traced (SmallVCM's SubPathState).
    struct SubPath {
        Ray ray;  ///< next segment
        Rgb throughput{1, 1, 1};
        int pathLength = 1;  ///< segments, including the one being traced
        /// false: the subpath starts with a planar measure (a light at infinity, or the
        /// orthographic camera's film), so its first segment adds no 1/d^2 [TR Sec. 5.1]
        bool isFiniteLight = true;
        /// Whether ub_mis_at_hit_volume converts the segment being traced with its d^2.
        int applyDistSqr() const { return pathLength > 1 || isFiniteLight; }
        bool specularPath = true;    ///< every scattering so far was specular (camera side)
        bool rayFromMedium = false;  ///< the ray starts at a medium vertex
        bool fromLight = false;      ///< a light subpath (else camera)
        ub_mis_partials mis{};       ///< dVCM, dVC, dVM
        MediumStack stack;           ///< media at the ray origin, for its direction (media only)
    };

    /// The vertex a traced segment (chain) ends at.
    struct PathVertex {
        bool inMedium = false;  ///< medium vertex at pos; else the surface hit
        Hit hit;                ///< surface vertex (hit.pos = pos)
        Vec3 pos;
        int mediumId = -1;
        float dist = 0.0f;  ///< from the previous vertex
        /// Free-flight pdfs of the segment in the tracing and the reverse direction (1 without
        /// media; render/medium_walk.h).
        float distPdfFwd = 1.0f, distPdfRev = 1.0f;
        /// Probability of passing the chain to the vertex (render/medium_walk.h).
        float passProb = 1.0f;
        Rgb mediumEmission{0.0f};  ///< collision estimate of medium emission (camera side)
        Vec3 geoNormal() const { return inMedium ? Vec3(0.0f) : hit.geoNormal; }
    };

    // Shared (vcm.cpp): traces state.ray to the next vertex (surface hit or, with media, a
    // medium vertex), updating throughput and medium stack. False if the ray escaped (then
    // *v holds the distance pdfs of the escape) or the path must end (black throughput).
    // beams: UPBP, append the beam pieces of the traced chain (photon beams for light
    // subpaths, query beams for camera subpaths; `tag` goes to ub_beam::pixel).
    bool traceToVertex(Rng& rng, SubPath& state, PathVertex* v, bool* escaped,
                       std::vector<ub_beam>* beams = nullptr, uint32_t tag = 0) const;
    /// R of the segment that reached v, of this subpath's beam kind (ub_mis_volume.h).
    float ratioIn(const SubPath& state, const PathVertex& v) const;
    /// R_out of the segment that reached v, for the previous vertex (the other kind).
    float ratioOut(const SubPath& state, const PathVertex& v) const;
    /// Completes the partials at v (ub_mis_at_hit_volume with the segment's pdfs).
    ub_mis_partials misAtHit(const SubPath& state, const PathVertex& v, float cosFix,
                             int applyDistSqr) const;
    /// Sets up the scattering function at v (dirFix = -state.ray.dir); false if degenerate.
    bool setupScatter(const PathVertex& v, const SubPath& state, bool fromLight,
                      VertexScatter* scatter) const;
    /// The medium stack for leaving vertex v along dir (surface: crossing it if dir goes
    /// to the other side). False on stack overflow.
    bool stackTowards(const PathVertex& v, const SubPath& state, const Vec3& dir,
                      MediumStack* out) const;

    /// What the light pass of one chunk of light subpaths stores.
    struct LightChunk {
        std::vector<LightVertex> vertices;
        std::vector<uint32_t> pathEnds;
        std::vector<ub_photon_point> photons;  ///< UPBP photon points
        std::vector<ub_beam> beams;            ///< UPBP photon beams
    };
    /// What the camera pass of one image row records for the estimate pass (UPBP).
    struct CameraRecords {
        std::vector<ub_query_point> points;
        std::vector<ub_beam> beams;
        std::vector<ub_surface_query> surf;  ///< upbp: surface queries (surface merging)
        uint64_t rejected = 0;               ///< camera-pass pixel estimates dropped by the guard
    };

    // Light pass (vcm_light.cpp): traces light subpaths [begin, end) of an iteration.
    void traceLightPaths(int iteration, size_t begin, size_t end, SplatBuffer::Chunk& splats,
                         LightChunk& out) const;
    bool startLightPath(Rng& rng, SubPath& state) const;
    void connectToCamera(Rng& rng, const SubPath& state, const PathVertex& v,
                         const VertexScatter& scatter, SplatBuffer::Chunk& splats) const;

    // Camera pass (vcm_camera.cpp).
    Rgb traceCameraPath(int x, int y, int iteration, CameraRecords* records) const;
    Rgb lightHitRadiance(const Light& light, const SubPath& state, const Vec3& rayDir,
                         const Vec3& hitPos, const Vec3& hitNormal, const Vec2& hitUv) const;
    Rgb directIllumination(Rng& rng, const SubPath& state, const PathVertex& v,
                           const VertexScatter& scatter) const;
    /// lv is the lightIndex-th stored vertex of its light subpath; lightScatters holds the
    /// scattering functions of that subpath's vertices set up so far (vertex_scatter.h).
    Rgb connectVertices(const LightVertex& lv, uint32_t lightIndex,
                        LightScatterCache& lightScatters, const SubPath& state, const PathVertex& v,
                        const VertexScatter& scatter) const;
    Rgb mergeVertices(const SubPath& state, const Hit& hit, const Bsdf& bsdf) const;
    /// mergeVertices for a Blend (no kernel-side BSDF state; surface_merging.cpp).
    Rgb mergeVerticesBlend(const SubPath& state, const Hit& hit, const Bsdf& bsdf) const;
    /// upbp's surface-merging pass (estimators/surface_merging.cpp) over the recorded surface
    /// queries: adds each query's estimate to its pixel of out and of layer, in query order.
    void estimateSurfaceQueries(Image& out, Image* layer);
    /// Its estimates of surfaceQueries_, by the kernel (cl) or the host twin (cl null).
    void surfaceEstimates(ClRuntime* cl, std::vector<Rgb>* perQuery);
    /// The estimate pass's input for this iteration's records (renderIteration, replay).
    VolumeEstimateInput volumeInput(const UpbpTechniques& techniques, ClRuntime* cl,
                                    bool beamKernels);

    // Shared: samples the next direction (Russian roulette, MIS update [TR (34)-(36)],
    // [TR (53)-(55)]), updates the medium stack and spawns the ray. Returns false if the
    // subpath ends. With nullNotCounted_, a null-lobe event decrements state.pathLength
    // (the caller's increment then leaves it unchanged: the vertex is not counted), and
    // onlyNull (the subpath is at its length limit) ends the subpath on any other event.
    bool sampleScattering(Rng& rng, const VertexScatter& scatter, const PathVertex& v,
                          SubPath& state, bool onlyNull = false) const;

    const Scene& scene_;
    RenderOptions options_;
    Algorithm algorithm_;
    bool useVC_ = false, useVM_ = false, lightTraceOnly_ = false, ppm_ = false;
    bool useMedia_ = false;                    ///< vlt/vbpt/upbp on a scene with media
    UpbpTechniques upbp_;                      ///< UPBP techniques (Algorithm::Upbp)
    int beamPaths_ = 0;                        ///< N_B
    float mediaRadius_ = 1;                    ///< what relative UPBP radii are fractions of
    std::unique_ptr<ClRuntime> cl_;            ///< OpenCL backend of the estimate pass, or null
    std::vector<ub_medium_info> deviceMedia_;  ///< with cl_: prepareDeviceMedia()
    bool beamKernels_ = false;                 ///< with cl_: pb2d, bp2d, bb1d as kernels
    std::string backendNote_;
    /// DepthCounting::kNonNullVertices: null-lobe vertices do not count towards the length.
    bool nullNotCounted_ = false;
    bool mediaEmit_ = false;  ///< some medium emits (sigma_a Le): camera medium vertices count
    std::vector<MediumStack> lightStacks_;  ///< media where each light's subpaths start
    float baseRadius_ = 0;
    float lightPickProb_ = 0;

    // Per-iteration state (renderIteration writes, the passes read).
    ub_mis_constants mis_{};
    float lightSubPathCount_ = 0;
    float vmNormalization_ = 0;  ///< 1 / (pi r^2 N_L)
    /// --max-memory: every record container and lookup reserves here before it grows.
    std::unique_ptr<MemoryBudget> budget_;
    std::vector<LightVertex> lightVertices_;
    std::vector<uint32_t> pathEnds_;  ///< light subpath i owns [pathEnds_[i-1], pathEnds_[i])
    HashGrid grid_;
    std::vector<LightChunk> lightChunks_;        ///< light pass output per chunk
    std::vector<CameraRecords> cameraRows_;      ///< camera pass records per image row
    std::vector<ub_photon_point> photonPoints_;  ///< UPBP records of the iteration
    std::vector<ub_beam> photonBeams_;
    std::vector<ub_query_point> queryPoints_;
    std::vector<ub_beam> queryBeams_;
    /// upbp with surf: surface merging runs as a batch pass (surfBatch_) over the surface
    /// light vertices (surfacePhotons_, which grid_ indexes) and the recorded queries.
    bool surfBatch_ = false;
    std::vector<LightVertex> surfacePhotons_;
    std::vector<ub_surface_query> surfaceQueries_;
    std::vector<float> coatingTables_;  ///< estimators/surface_merging.h coatingTables()
    size_t lastSurfPairs_ = 0;
    double lastSurfSeconds_ = 0;
    float volumeRadius_[4] = {0, 0, 0, 0};  ///< this iteration's radii (UB_TECH_*), 0: off
    std::vector<std::string> layerNames_;   ///< UPBP technique layers
    std::vector<Image> layers_;             ///< the last iteration's layers
    double lastBuildSeconds_ = 0, lastEstimateSeconds_ = 0;
    /// Wall-clock seconds of the last iteration's light pass (tracing the light subpaths, light
    /// tracing to the camera included) and camera pass (camera subpaths, their connections and
    /// the recording of queries), for iterationSummary.
    double lastLightSeconds_ = 0, lastCameraSeconds_ = 0;
    size_t lastPairs_[4] = {0, 0, 0, 0};
    SplatBuffer splats_;
    // Contribution guard (render/contribution_guard.h): technique 0 is the camera pass and the
    // light-tracing splats (the algorithm, or UPBP's first layer), then UPBP's other layers.
    std::vector<std::string> techniques_;
    std::vector<ContributionGuard> guards_;      ///< per technique
    std::vector<uint64_t> rejected_;             ///< per technique, all iterations
    int surfTechnique_ = -1;                     ///< UPBP layers: index of "surf"
    int volumeTechnique_[4] = {-1, -1, -1, -1};  ///< UB_TECH_* -> technique index
};

/// Russian-roulette continuation probability of the bidirectional engine at a vertex with
/// this BSDF. The MIS partials assume that a light and a camera subpath passing through a
/// vertex would continue with the same probability (SmallVCM's albedo-based roulette).
/// Bsdf::continuationProb() depends on dirFix for rough conductors (Fresnel at dirFix), so
/// for those the direction-free bound max(specular) is used; otherwise it is the same.
float vcmContinuationProb(const Bsdf& bsdf);

std::unique_ptr<Integrator> makeVertexCM(const Scene& scene, const RenderOptions& options);

}  // namespace ub
