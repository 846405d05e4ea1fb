// Registry of the rendering algorithms selectable by name (`unibeam render -a NAME`).
//
// To add an algorithm: declare its factory in its own header (same signature as
// IntegratorFactory below, e.g. `std::unique_ptr<Integrator> makeLightTracer(const Scene&,
// const RenderOptions&)`), include that header here and add one line to kIntegrators.
// The order of the table is the order names are listed in help texts and errors.
#include "render/integrator.h"

#include "core/error.h"
#include "render/pt.h"
#include "render/upbp_techniques.h"
#include "render/vcm.h"
#include "render/vpt.h"

namespace ub {

namespace {

using IntegratorFactory = std::unique_ptr<Integrator> (*)(const Scene&, const RenderOptions&);

struct IntegratorEntry {
    const char* name;
    IntegratorFactory make;
    bool handlesMedia;  ///< false: scenes with participating media are rejected
};

const IntegratorEntry kIntegrators[] = {
    {"pt", makePathTracer, false},     // path tracing, NEE + MIS (render/pt.h)
    {"lt", makeVertexCM, false},       // light tracing (render/vcm.h)
    {"bpt", makeVertexCM, false},      // bidirectional path tracing, recursive MIS (render/vcm.h)
    {"ppm", makeVertexCM, false},      // progressive photon mapping (render/vcm.h)
    {"bpm", makeVertexCM, false},      // bidirectional photon mapping (render/vcm.h)
    {"vcm", makeVertexCM, true},       // vertex connection and merging; upbp:bpt+surf in media
    {"vpt", makeVolPathTracer, true},  // volumetric path tracing, NEE + MIS (render/vpt.h)
    {"vlt", makeVertexCM, true},       // volumetric light tracing (render/vcm.h, media)
    {"vbpt", makeVertexCM, true},      // volumetric bidirectional path tracing (render/vcm.h)
    {"upbp", makeVertexCM, true},      // UPBP, all techniques or upbp:T1+T2 (render/vcm.h)
};

}  // namespace

std::vector<std::string> integratorNames() {
    std::vector<std::string> names;
    for (const auto& e : kIntegrators) names.emplace_back(e.name);
    return names;
}

std::unique_ptr<Integrator> makeIntegrator(const Scene& scene, const RenderOptions& options) {
    for (const auto& e : kIntegrators)
        if (options.algorithm == e.name ||
            (std::string(e.name) == "upbp" && isUpbpAlgorithm(options.algorithm))) {
            if (!e.handlesMedia && scene.hasMedia()) {
                std::string media;
                for (const auto& m : kIntegrators)
                    if (m.handlesMedia) media += (media.empty() ? "" : ", ") + std::string(m.name);
                throw InputError(scene.sourceFile,
                                 "the scene has participating media, which '" + options.algorithm +
                                     "' does not render (it would ignore them); use a volumetric "
                                     "algorithm: " +
                                     media);
            }
            return e.make(scene, options);
        }
    std::string valid;
    for (const auto& e : kIntegrators) valid += (valid.empty() ? "" : ", ") + std::string(e.name);
    throw InputError("", "unknown algorithm '" + options.algorithm + "' (valid: " + valid + ")");
}

}  // namespace ub
