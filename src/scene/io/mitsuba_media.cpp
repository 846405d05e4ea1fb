// Mitsuba <medium> plugins -> unibeam media (docs/mitsuba.md lists the mapping):
// homogeneous (sigma_t, albedo, scale) and heterogeneous with a gridvolume
// (.vol or .vdb; 1 channel, or 3 for a chromatic extinction) or constvolume extinction, a
// constant albedo or an albedo
// gridvolume (1 or 3 channels, its own to_world and filter; scene/albedo_grid.h),
// isotropic or HG phase. Mitsuba's gridvolume interpolates trilinearly by default: that maps
// onto GridFilter::kTrilinear (exact transmittance, scene/medium_trilinear.h);
// filter_type="nearest" onto the piecewise-constant default.
#include <algorithm>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "scene/albedo_grid.h"
#include "scene/io/mitsuba_build.h"
#include "scene/medium.h"
#include "scene/vol_grid.h"

namespace ub {

namespace {

float readPhase(XmlReader& r, const XmlObject& medium) {
    const XmlObject* ph = r.child(medium, "phase", "");
    if (!ph) return 0.0f;
    float g = 0.0f;
    if (ph->type == "hg")
        g = r.getFloatIn(*ph, "g", 0.8f, -1.0f, 1.0f, true, true);
    else if (ph->type != "isotropic")
        r.unsupportedPlugin(*ph, {"isotropic", "hg"});
    r.checkUnused(*ph);
    return g;
}

/// A spectrally constant or RGB value given directly or as <volume type="constvolume">.
bool readConstant(XmlReader& r, const XmlObject& o, const std::string& name, Rgb def, ColorUse use,
                  Rgb* out) {
    if (const XmlObject* v = r.child(o, "volume", name)) {
        if (v->type != "constvolume") return false;
        *out = r.getColor(*v, "value", Rgb(1.0f), use);
        // A constant is the same in every frame: to_world (valid, as Mitsuba requires) changes
        // nothing.
        r.getTransform(*v, "to_world");
        r.checkUnused(*v);
        return true;
    }
    *out = r.getColor(o, name, def, use);
    return true;
}

/// What a gridvolume holds: the extinction (sigma_t) or the albedo; either has 1 channel
/// (grey) or 3 (RGB: a chromatic extinction, Medium::heterogeneousRgb).
enum class VolumeRole { kSigmaT, kAlbedo };

struct GridVolume {
    std::vector<std::shared_ptr<const VdbGrid>> grids;  ///< one per channel
    Transform localToWorld;
    GridMediumOptions options;
    bool domainGiven = false;          ///< options.domainLo/Hi hold the full extent of a .vol grid
    GridWrap wrap = GridWrap::kClamp;  ///< albedo volumes: wrap_mode
    std::string label;                 ///< file name as written in the scene, and the grid
};

bool readGridVolume(MitsubaBuild& b, const XmlObject& v, VolumeRole role, GridVolume* out) {
    XmlReader& r = b.r;
    const size_t before = r.errorCount();
    const bool albedo = role == VolumeRole::kAlbedo;
    Transform toWorld = r.getTransform(v, "to_world");
    bool useBbox = r.getBool(v, "use_grid_bbox", false);
    std::string filter = r.getString(v, "filter_type", "trilinear");
    if (filter == "trilinear")
        out->options.filter = GridFilter::kTrilinear;
    else if (filter == "nearest")
        out->options.filter = GridFilter::kNearest;
    else
        r.error(v.find("filter_type")->pos,
                v.label() + ": filter_type '" + filter + "' is not one of trilinear, nearest");
    std::string wrap = r.getString(v, "wrap_mode", "clamp");
    if (wrap == "repeat" || wrap == "mirror") {
        // An albedo lookup wraps (scene/albedo_grid.h); an extinction grid's tracking is
        // bounded by its box, where clamp and the other modes agree only inside.
        if (albedo)
            out->wrap = wrap == "repeat" ? GridWrap::kRepeat : GridWrap::kMirror;
        else
            r.error(v.find("wrap_mode")->pos,
                    v.label() + ": wrap_mode '" + wrap +
                        "' is supported on albedo volumes only (an extinction grid takes "
                        "clamp, the default)");
    } else if (wrap != "clamp") {
        r.error(v.find("wrap_mode")->pos,
                v.label() + ": wrap_mode '" + wrap + "' is not one of clamp, repeat, mirror");
    }
    // raw only changes colour data in Mitsuba's spectral variants (no spectral upsampling);
    // the rgb variants, which unibeam follows, use the values as stored either way.
    r.getBool(v, "raw", false);
    // unibeam's extension for .vdb files: the grid to read (Mitsuba 3 reads no .vdb).
    const std::string defaultGrid = albedo ? "albedo" : "density";
    const bool hasGridName = r.has(v, "grid_name");
    std::string gridName = r.getString(v, "grid_name", defaultGrid);
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
            if (hasGridName)
                r.error(v.find("grid_name")->pos,
                        v.label() +
                            ": grid_name applies to .vdb files only (a .vol file holds "
                            "one grid)");
            VolGrid vol = readVolFile(path);
            out->label = "'" + file + "'";
            for (int c = 0; c < vol.channels; ++c) {
                DenseFloatGrid dense = volChannelToDense(vol, c);
                const bool zero = std::all_of(dense.values.begin(), dense.values.end(),
                                              [](float x) { return x == 0.0f; });
                if (albedo)
                    out->grids.push_back(
                        VdbGrid::fromDenseChecked(dense, "albedo", path, "albedo", 1.0f));
                else if (zero && vol.channels == 3)  // a channel without extinction
                    out->grids.push_back(VdbGrid::constant(0.0f, path));
                else
                    out->grids.push_back(VdbGrid::fromDense(dense, "density", path));
            }
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
            out->domainGiven = true;
        } else if (ext == ".vdb") {
            if (useBbox)
                r.error(v.find("use_grid_bbox")->pos,
                        v.label() +
                            ": use_grid_bbox does not apply to .vdb files (their own "
                            "transform places the grid)");
            out->label = "'" + file + "' grid '" + gridName + "'";
            if (albedo)
                out->grids = loadVdbAlbedoChannels(path, gridName);
            else  // a float grid (grey) or a vec3 grid (chromatic sigma_t)
                out->grids = VdbGrid::loadChannels(path, gridName, "sigma_t",
                                                   std::numeric_limits<float>::infinity());
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
    // A hint that sigma_t is the same in every channel (Mitsuba then samples distances with the
    // first channel): the same image when it is true of sigma_t, checked below.
    const XmlProperty* spectralHint = o.find("has_spectral_extinction");
    const bool spectralExtinction = r.getBool(o, "has_spectral_extinction", true);
    auto checkGrey = [&](const Rgb& st) {
        if (!spectralExtinction && !(st.x == st.y && st.y == st.z))
            r.error(spectralHint->pos, o.label() +
                                           ": has_spectral_extinction = false with a sigma_t "
                                           "that differs between channels (Mitsuba would track "
                                           "the first channel only); give a grey sigma_t or "
                                           "remove the parameter");
    };
    const float g = readPhase(r, o);
    Rgb albedo(0.75f);
    const XmlObject* albedoVol = nullptr;  // a gridvolume albedo
    GridVolume albedoGrid;
    if (!readConstant(r, o, "albedo", Rgb(0.75f), ColorUse::Reflectance, &albedo)) {
        const XmlObject* v = r.child(o, "volume", "albedo");
        if (v->type != "gridvolume") {
            r.unsupportedPlugin(*v, {"gridvolume", "constvolume"});
        } else if (readGridVolume(b, *v, VolumeRole::kAlbedo, &albedoGrid)) {
            albedoVol = v;
        }
    }
    const XmlObject* vol = nullptr;
    GridVolume gv;
    bool ok = true;
    Rgb constSigmaT(1.0f);
    if (o.type == "homogeneous") {
        if (!readConstant(r, o, "sigma_t", Rgb(1.0f), ColorUse::Unbounded, &constSigmaT)) {
            const XmlObject* v = r.child(o, "volume", "sigma_t");
            r.error(v->pos, o.label() + ": sigma_t must be constant in a homogeneous medium");
        }
        checkGrey(constSigmaT);
        r.checkUnused(o);
        if (r.errorCount() != before) return false;
        if (!albedoVol) {
            const Rgb st = constSigmaT * scale, ss = albedo * st;
            *out = Medium::homogeneous(vmax(st - ss, Rgb(0.0f)), ss, g);
            return true;
        }
        // Mitsuba's homogeneous medium takes an albedo volume too, looked up at each
        // collision: a grid medium of constant density with that albedo grid (below).
    } else if (o.type != "heterogeneous") {
        r.unsupportedPlugin(o, {"homogeneous", "heterogeneous"});
        return false;
    } else {  // heterogeneous
        vol = r.child(o, "volume", "sigma_t");
        if (!vol) {
            ok = readConstant(r, o, "sigma_t", Rgb(1.0f), ColorUse::Unbounded, &constSigmaT);
        } else if (vol->type == "constvolume") {
            ok = readConstant(r, o, "sigma_t", Rgb(1.0f), ColorUse::Unbounded, &constSigmaT);
            vol = nullptr;
        } else if (vol->type == "gridvolume") {
            ok = readGridVolume(b, *vol, VolumeRole::kSigmaT, &gv);
        } else {
            r.unsupportedPlugin(*vol, {"gridvolume", "constvolume"});
            ok = false;
        }
        if (!vol && ok) checkGrey(constSigmaT);
        if (vol && ok && gv.grids.size() == 3 && spectralHint && !spectralExtinction)
            r.error(spectralHint->pos,
                    o.label() +
                        ": has_spectral_extinction = false with a 3-channel sigma_t grid "
                        "(Mitsuba would track the first channel only); give a 1-channel grid "
                        "or remove the parameter");
        r.checkUnused(o);
        if (!ok || r.errorCount() != before) return false;
    }
    try {
        if (!vol && albedoVol) {  // constant extinction, varying albedo: constant grids
            const bool grey = constSigmaT.x == constSigmaT.y && constSigmaT.y == constSigmaT.z;
            if (grey) {
                *out = Medium::heterogeneous(VdbGrid::constant(1.0f, "constant sigma_t"),
                                             constSigmaT.x * scale, albedo, g, Transform());
            } else {  // one constant grid per channel: a chromatic extinction
                std::shared_ptr<const VdbGrid> channels[3];
                for (int c = 0; c < 3; ++c)
                    channels[c] = VdbGrid::constant(constSigmaT[c], "constant sigma_t");
                *out = Medium::heterogeneousRgb(channels, scale, albedo, g, Transform());
            }
        } else if (!vol) {  // a constant extinction: the same as homogeneous
            const Rgb st = constSigmaT * scale, ss = albedo * st;
            *out = Medium::homogeneous(vmax(st - ss, Rgb(0.0f)), ss, g);
        } else if (gv.grids.size() == 3) {  // chromatic extinction
            *out = Medium::heterogeneousRgb(gv.grids.data(), scale, albedo, g, gv.localToWorld,
                                            gv.options);
        } else {
            *out =
                Medium::heterogeneous(gv.grids[0], scale, albedo, g, gv.localToWorld, gv.options);
        }
        if (albedoVol) {
            const GridMediumOptions& ao = albedoGrid.options;
            out->albedoGrid = AlbedoGrid::make(albedoGrid.grids, ao.filter, albedoGrid.localToWorld,
                                               albedoGrid.domainGiven ? ao.domainLo : nullptr,
                                               albedoGrid.domainGiven ? ao.domainHi : nullptr,
                                               albedoGrid.label, albedoGrid.wrap);
        }
    } catch (const std::invalid_argument& e) {
        r.error(o.pos, o.label() + ": " + e.what());
        return false;
    } catch (const InputError& e) {
        for (const Diagnostic& d : e.diagnostics())
            r.error(albedoVol ? albedoVol->pos : o.pos, o.label() + ": " + d.message);
        return false;
    }
    return true;
}

}  // namespace ub
