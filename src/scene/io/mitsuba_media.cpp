// Mitsuba <medium> plugins -> unibeam media (docs/mitsuba.md lists the mapping):
// homogeneous (sigma_t, albedo, scale) and heterogeneous with a gridvolume
// (.vol or .vdb) or constvolume extinction, constant albedo, isotropic or HG
// phase. Mitsuba's gridvolume interpolates trilinearly by default: that maps
// onto GridFilter::kTrilinear (exact transmittance, scene/medium_trilinear.h);
// filter_type="nearest" onto the piecewise-constant default.
#include <filesystem>
#include <stdexcept>

#include "scene/io/mitsuba_build.h"
#include "scene/medium.h"
#include "scene/vol_grid.h"

namespace ub {

namespace {

float readPhase(XmlReader& r, const XmlObject& medium) {
    const XmlObject* ph = r.child(medium, "phase", "");
    if (!ph) return 0.0f;
    float g = 0.0f;
    if (ph->type == "hg") g = r.getFloatIn(*ph, "g", 0.8f, -1.0f, 1.0f, true, true);
    else if (ph->type != "isotropic") r.unsupportedPlugin(*ph, {"isotropic", "hg"});
    r.checkUnused(*ph);
    return g;
}

/// A spectrally constant or RGB value given directly or as <volume type="constvolume">.
bool readConstant(XmlReader& r, const XmlObject& o, const std::string& name, Rgb def,
                  ColorUse use, Rgb* out) {
    if (const XmlObject* v = r.child(o, "volume", name)) {
        if (v->type != "constvolume") return false;
        *out = r.getColor(*v, "value", Rgb(1.0f), use);
        r.checkUnused(*v);
        return true;
    }
    *out = r.getColor(o, name, def, use);
    return true;
}

struct GridVolume {
    std::shared_ptr<const VdbGrid> grid;
    Transform localToWorld;
    GridMediumOptions options;
};

bool readGridVolume(MitsubaBuild& b, const XmlObject& v, GridVolume* out) {
    XmlReader& r = b.r;
    const size_t before = r.errorCount();
    Transform toWorld = r.getTransform(v, "to_world");
    bool useBbox = r.getBool(v, "use_grid_bbox", false);
    std::string filter = r.getString(v, "filter_type", "trilinear");
    if (filter == "trilinear") out->options.filter = GridFilter::kTrilinear;
    else if (filter == "nearest") out->options.filter = GridFilter::kNearest;
    else r.error(v.find("filter_type")->pos, v.label() + ": filter_type '" + filter +
                                                 "' is not one of trilinear, nearest");
    std::string wrap = r.getString(v, "wrap_mode", "clamp");
    if (wrap != "clamp")
        r.error(v.find("wrap_mode")->pos, v.label() + ": wrap_mode '" + wrap +
                                              "' is not supported (only clamp, the default)");
    r.getBool(v, "raw", false);  // only changes colour data; a density grid is read as is
    std::string file = r.getString(v, "filename", "");
    r.checkUnused(v);
    if (file.empty()) {
        r.error(v.pos, v.label() + ": needs <string name=\"filename\"> (a .vol or .vdb file)");
        return false;
    }
    std::string path = b.resolveFile(v, "filename", file);
    if (path.empty() || r.errorCount() != before) return false;
    const XmlPos& fpos = v.find("filename")->pos;
    std::string ext = std::filesystem::path(path).extension().string();
    try {
        if (ext == ".vol") {
            VolGrid vol = readVolFile(path);
            if (vol.channels != 1) {
                r.error(fpos, v.label() + ": '" + file + "' has " +
                                  std::to_string(vol.channels) +
                                  " channels; an extinction grid needs 1");
                return false;
            }
            out->grid = VdbGrid::fromDense(volChannelToDense(vol, 0), "density", path);
            Transform unit = volCellToUnitCube(vol);
            if (useBbox)
                unit = Transform::translate(vol.bboxMin) *
                       Transform::scale(vol.bboxMax - vol.bboxMin) * unit;
            // cell space = index + 1/2 (scene/medium.h), so local (index) -> world is
            // to_world * unit * translate(+1/2).
            out->localToWorld = toWorld * unit * Transform::translate(Vec3(0.5f));
            const int n[3] = {vol.nx, vol.ny, vol.nz};
            for (int a = 0; a < 3; ++a) {
                out->options.domainLo[a] = 0;
                out->options.domainHi[a] = n[a] - 1;
            }
        } else if (ext == ".vdb") {
            if (useBbox)
                r.error(v.find("use_grid_bbox")->pos,
                        v.label() + ": use_grid_bbox does not apply to .vdb files (their own "
                                    "transform places the grid)");
            out->grid = VdbGrid::load(path, "density");
            out->localToWorld = toWorld;
        } else {
            r.error(fpos, v.label() + ": '" + file + "' is neither a .vol nor a .vdb file");
            return false;
        }
    } catch (const InputError& e) {
        for (const Diagnostic& d : e.diagnostics()) r.error(fpos, v.label() + ": " + d.format());
        return false;
    }
    return r.errorCount() == before;
}

}  // namespace

bool buildMitsubaMedium(MitsubaBuild& b, const XmlObject& o, Medium* out) {
    XmlReader& r = b.r;
    const size_t before = r.errorCount();
    const float scale = r.getFloatIn(o, "scale", 1.0f, 0.0f, kInf);
    r.getBool(o, "sample_emitters", true);  // sampling strategy only
    const float g = readPhase(r, o);
    Rgb albedo(0.75f);
    if (!readConstant(r, o, "albedo", Rgb(0.75f), ColorUse::Reflectance, &albedo)) {
        const XmlObject* v = r.child(o, "volume", "albedo");
        r.error(v->pos, o.label() + ": a spatially varying albedo (" + v->label() +
                            ") is not supported yet; give a constant <rgb name=\"albedo\">");
    }
    if (o.type == "homogeneous") {
        Rgb sigmaT(1.0f);
        if (!readConstant(r, o, "sigma_t", Rgb(1.0f), ColorUse::Unbounded, &sigmaT)) {
            const XmlObject* v = r.child(o, "volume", "sigma_t");
            r.error(v->pos, o.label() + ": sigma_t must be constant in a homogeneous medium");
        }
        r.checkUnused(o);
        if (r.errorCount() != before) return false;
        const Rgb st = sigmaT * scale, ss = albedo * st;
        *out = Medium::homogeneous(vmax(st - ss, Rgb(0.0f)), ss, g);
        return true;
    }
    if (o.type != "heterogeneous") {
        r.unsupportedPlugin(o, {"homogeneous", "heterogeneous"});
        return false;
    }
    const XmlObject* vol = r.child(o, "volume", "sigma_t");
    GridVolume gv;
    bool ok = true;
    Rgb constSigmaT(1.0f);
    if (!vol) {
        ok = readConstant(r, o, "sigma_t", Rgb(1.0f), ColorUse::Unbounded, &constSigmaT);
    } else if (vol->type == "constvolume") {
        ok = readConstant(r, o, "sigma_t", Rgb(1.0f), ColorUse::Unbounded, &constSigmaT);
        vol = nullptr;
    } else if (vol->type == "gridvolume") {
        ok = readGridVolume(b, *vol, &gv);
    } else {
        r.unsupportedPlugin(*vol, {"gridvolume", "constvolume"});
        ok = false;
    }
    r.checkUnused(o);
    if (!ok || r.errorCount() != before) return false;
    try {
        if (!vol) {  // a constant extinction: the same as homogeneous
            const Rgb st = constSigmaT * scale, ss = albedo * st;
            *out = Medium::homogeneous(vmax(st - ss, Rgb(0.0f)), ss, g);
        } else {
            *out = Medium::heterogeneous(gv.grid, scale, albedo, g, gv.localToWorld, gv.options);
        }
    } catch (const std::invalid_argument& e) {
        r.error(o.pos, o.label() + ": " + e.what());
        return false;
    }
    return true;
}

}  // namespace ub
