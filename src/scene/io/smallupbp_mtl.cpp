// SmallUPBP's .mtl reading (ObjReader::readMtl): it uses newmtl, Ns, Kd, Ks,
// Ka, Ke and map_Kd (a texture it then never applies), recognised by first
// letters: 'n' newmtl, 'N' + 's' Ns, 'K' + d/s/a/e, 'm' a texture map.
// Standard MTL statements it skips (Ni, d, Tr, Tf, illum, other maps) are
// skipped here too; any other statement is an error.
#include <algorithm>
#include <fstream>
#include <sstream>

#include "scene/io/smallupbp_files.h"
#include "scene/io/smallupbp_lexer.h"

namespace ub {

namespace {

// Standard MTL statements SmallUPBP skips (their values do not change its image).
bool isSkippedMtlStatement(const std::string& k) {
    static const char* kSkipped[] = {"Ni", "d",  "Tr", "Tf",  "illum", "sharpness", "Pr",
                                     "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor"};
    for (const char* s : kSkipped)
        if (k == s) return true;
    return false;
}

bool isTextureStatement(const std::string& k) {
    return k.rfind("map_", 0) == 0 || k == "bump" || k == "disp" || k == "decal" || k == "refl" ||
           k == "norm";
}

}  // namespace

bool readUpbpTextFile(const std::string& path, const std::string& what, std::string* text,
                      Diagnostics& diags, const std::string& referrer, int line, int column) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        if (referrer.empty())
            diags.error({path, 0, 0, "", "cannot open the " + what});
        else
            diags.error(
                {referrer, line, column, "", "cannot open the " + what + " '" + path + "'"});
        return false;
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    *text = ss.str();
    return true;
}

void readUpbpMtl(const std::string& path, std::vector<UpbpMaterial>* materials,
                 Diagnostics& diags) {
    std::string text;
    if (!readUpbpTextFile(path, "material library", &text, diags)) return;
    UpbpReader r(path, std::move(text), diags);
    UpbpLexer& lex = r.lexer();
    UpbpMaterial* current = nullptr;
    UpbpToken kw;
    bool warnedTexture = false;
    while (lex.next(&kw)) {
        const std::string& k = kw.text;
        if (k[0] == '#') {
            lex.restOfLine();
            continue;
        }
        if (k[0] == 'n') {
            if (k != "newmtl")
                r.warning(kw, "'" + k +
                                  "' read as 'newmtl' (SmallUPBP recognises it by its "
                                  "first letter)");
            UpbpToken name;
            if (!r.word(kw, "newmtl", "a material name", &name)) continue;
            for (const UpbpMaterial& m : *materials)
                if (m.name == name.text)
                    r.warning(name, "material '" + name.text + "' is defined again (first at " +
                                        "line " + std::to_string(m.pos.line) +
                                        "); as in SmallUPBP, references use the first one");
            UpbpMaterial m;
            m.name = name.text;
            m.pos = {kw.line, kw.column};
            materials->push_back(m);
            current = &materials->back();
            continue;
        }
        const bool ns = k[0] == 'N' && k.size() > 1 && k[1] == 's';
        const bool colour = k[0] == 'K' && k.size() > 1 &&
                            (k[1] == 'd' || k[1] == 's' || k[1] == 'a' || k[1] == 'e');
        const bool texture = k[0] == 'm' || isTextureStatement(k);
        if (ns || colour || texture || isSkippedMtlStatement(k)) {
            if (!current) {
                r.error(kw, "'" + k + "' before any 'newmtl' (expected 'newmtl NAME' first)");
                lex.restOfLine();
                continue;
            }
        }
        if (ns) {
            if (k != "Ns") r.warning(kw, "'" + k + "' read as 'Ns' (as SmallUPBP does)");
            float v = 0.0f;
            if (!r.numbers(kw, "Ns", 1, "Phong exponent", &v)) continue;
            if (v < 0.0f) {
                r.error(kw, "'Ns' must be >= 0 (got " + std::to_string(v) + ")");
                continue;
            }
            current->shininess = v;
        } else if (colour) {
            const std::string name = std::string("K") + k[1];
            if (k != name) r.warning(kw, "'" + k + "' read as '" + name + "' (as SmallUPBP does)");
            float c[3];
            if (!r.numbers(kw, name, 3, "r g b", c)) continue;
            if (c[0] < 0.0f || c[1] < 0.0f || c[2] < 0.0f) {
                r.error(kw, "'" + name + "' must not be negative");
                continue;
            }
            if ((k[1] == 'd' || k[1] == 's') && std::max({c[0], c[1], c[2]}) > 1.0f)
                r.warning(kw, "'" + name +
                                  "' above 1 reflects more light than arrives (the "
                                  "material creates energy); read as written, as SmallUPBP does");
            if (k[1] == 'd') current->diffuse = Rgb(c[0], c[1], c[2]);
            if (k[1] == 's') current->specular = Rgb(c[0], c[1], c[2]);
            if (k[1] == 'e') current->emission = Rgb(c[0], c[1], c[2]);
            // Ka (ambient) is read and unused, as in SmallUPBP.
        } else if (texture) {
            if (k[0] == 'm' && k.rfind("map_", 0) != 0) {
                r.error(kw, "unknown statement '" + k +
                                "' (SmallUPBP would read it as a texture map; MTL maps are "
                                "named map_Kd, map_Ks, ...)");
                lex.restOfLine();
                continue;
            }
            if (!warnedTexture)
                r.warning(kw, "texture '" + k +
                                  "' ignored: unibeam's SmallUPBP reader, like SmallUPBP, "
                                  "renders untextured materials");
            warnedTexture = true;
            lex.restOfLine();
        } else if (isSkippedMtlStatement(k)) {
            lex.restOfLine();  // standard MTL that SmallUPBP does not use
        } else {
            r.error(kw, "unknown .mtl statement '" + k +
                            "' (SmallUPBP reads newmtl, Ns, Kd, Ks, Ka, Ke and skips Ni, d, "
                            "Tr, Tf, illum and texture maps)");
            lex.restOfLine();
        }
    }
}

}  // namespace ub
