// Parsing of UPBP technique sets (see upbp_techniques.h).
#include "render/upbp_techniques.h"

#include "core/error.h"

namespace ub {

namespace {
constexpr const char* kValid = "bpt, surf, pp3d, pb2d, bp2d, bb1d";
}

std::string UpbpTechniques::describe() const {
    std::string s;
    auto add = [&](bool on, const char* name) {
        if (on) s += (s.empty() ? "" : "+") + std::string(name);
    };
    add(bpt, "bpt");
    add(surf, "surf");
    add(pp3d, "pp3d");
    add(pb2d, "pb2d");
    add(bp2d, "bp2d");
    add(bb1d, "bb1d");
    return s;
}

bool isUpbpAlgorithm(const std::string& algorithm) {
    return algorithm == "upbp" || algorithm.rfind("upbp:", 0) == 0;
}

UpbpTechniques parseUpbpTechniques(const std::string& algorithm) {
    UpbpTechniques t;
    if (algorithm == "upbp") {
        t.bpt = t.surf = t.pp3d = t.pb2d = t.bp2d = t.bb1d = true;
        return t;
    }
    if (!isUpbpAlgorithm(algorithm))
        throw InputError("", "not a UPBP algorithm: '" + algorithm + "'");
    const std::string list = algorithm.substr(5);
    if (list.empty())
        throw InputError("", "algorithm '" + algorithm +
                                 "': no technique after 'upbp:' (expected upbp:T1+T2+... with "
                                 "T one of " +
                                 kValid + ")");
    size_t start = 0;
    while (start <= list.size()) {
        size_t end = list.find('+', start);
        if (end == std::string::npos) end = list.size();
        const std::string name = list.substr(start, end - start);
        bool* flag = name == "bpt"    ? &t.bpt
                     : name == "surf" ? &t.surf
                     : name == "pp3d" ? &t.pp3d
                     : name == "pb2d" ? &t.pb2d
                     : name == "bp2d" ? &t.bp2d
                     : name == "bb1d" ? &t.bb1d
                                      : nullptr;
        if (!flag)
            throw InputError("", "algorithm '" + algorithm + "': unknown technique '" + name +
                                     "' (valid: " + kValid + ")");
        if (*flag)
            throw InputError(
                "", "algorithm '" + algorithm + "': technique '" + name + "' is given twice");
        *flag = true;
        start = end + 1;
    }
    return t;
}

}  // namespace ub
