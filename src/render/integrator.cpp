// Registry of the rendering algorithms selectable by name (`unibeam render -a NAME`).
//
// To add an algorithm: declare its factory in its own header (same signature as
// IntegratorFactory below, e.g. `std::unique_ptr<Integrator> makeLightTracer(const Scene&,
// const RenderOptions&)`), include that header here and add one line to kIntegrators.
// The order of the table is the order names are listed in help texts and errors.
#include "render/integrator.h"

#include "core/error.h"
#include "render/pt.h"
#include "render/vcm.h"

namespace ub {

namespace {

using IntegratorFactory = std::unique_ptr<Integrator> (*)(const Scene&, const RenderOptions&);

struct IntegratorEntry {
    const char* name;
    IntegratorFactory make;
};

const IntegratorEntry kIntegrators[] = {
    {"pt", makePathTracer},  // path tracing, NEE + MIS (render/pt.h)
    {"lt", makeVertexCM},    // light tracing (render/vcm.h)
    {"bpt", makeVertexCM},   // bidirectional path tracing, recursive MIS (render/vcm.h)
    {"ppm", makeVertexCM},   // progressive photon mapping (render/vcm.h)
    {"bpm", makeVertexCM},   // bidirectional photon mapping (render/vcm.h)
    {"vcm", makeVertexCM},   // vertex connection and merging (render/vcm.h)
};

}  // namespace

std::vector<std::string> integratorNames() {
    std::vector<std::string> names;
    for (const auto& e : kIntegrators) names.emplace_back(e.name);
    return names;
}

std::unique_ptr<Integrator> makeIntegrator(const Scene& scene, const RenderOptions& options) {
    for (const auto& e : kIntegrators)
        if (options.algorithm == e.name) return e.make(scene, options);
    std::string valid;
    for (const auto& e : kIntegrators) valid += (valid.empty() ? "" : ", ") + std::string(e.name);
    throw InputError("", "unknown algorithm '" + options.algorithm + "' (valid: " + valid + ")");
}

}  // namespace ub
