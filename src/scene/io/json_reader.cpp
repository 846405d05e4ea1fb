#include "scene/io/json_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ub {

std::string formatNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%g", v);
    return buf;
}

namespace {

std::string fmt(double v) {
    return formatNumber(v);
}

bool isFiniteFloat(double d) {
    return std::isfinite(d) && std::isfinite(float(d));
}

}  // namespace

bool NumberRange::contains(double v) const {
    bool okLo = loOpen ? v > lo : v >= lo;
    bool okHi = hiOpen ? v < hi : v <= hi;
    return okLo && okHi;
}

std::string NumberRange::describe() const {
    bool hasLo = lo > -1e299, hasHi = hi < 1e299;
    if (!hasLo && !hasHi) return "a number";
    if (hasLo && !hasHi) return std::string("a number ") + (loOpen ? "> " : ">= ") + fmt(lo);
    if (!hasLo) return std::string("a number ") + (hiOpen ? "< " : "<= ") + fmt(hi);
    return "a number in " + std::string(loOpen ? "(" : "[") + fmt(lo) + ", " + fmt(hi) +
           (hiOpen ? ")" : "]");
}

int editDistance(const std::string& a, const std::string& b) {
    std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) prev[j] = int(j);
    for (size_t i = 1; i <= a.size(); ++i) {
        cur[0] = int(i);
        for (size_t j = 1; j <= b.size(); ++j) {
            int sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
        }
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates) {
    int best = 3;
    std::string match;
    for (const auto& c : candidates) {
        int d = editDistance(word, c);
        if (d < best) {
            best = d;
            match = c;
        }
    }
    return match.empty() ? "" : " (did you mean '" + match + "'?)";
}

std::string joinNames(const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s.empty() ? "none" : s;
}

std::string JsonReader::describeValue(const Json& v) {
    std::string text = v.dump();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    switch (v.type()) {
        case Json::value_t::null:
            return "null";
        case Json::value_t::boolean:
            return "a boolean (" + text + ")";
        case Json::value_t::string:
            return "a string (" + text + ")";
        case Json::value_t::array:
            return v.empty() ? "an empty array" : "an array (" + text + ")";
        case Json::value_t::object:
            return "an object";
        default:
            return v.is_number() ? "the number " + text : "a " + std::string(v.type_name());
    }
}

Diagnostic JsonReader::make(const std::string& ptr, SourcePos pos,
                            const std::string& message) const {
    Diagnostic d;
    d.file = file_;
    d.line = pos.line;
    d.column = pos.column;
    d.where = ptr.empty() ? "/" : ptr;
    d.message = message;
    return d;
}

size_t JsonReader::errorCount() const {
    size_t n = 0;
    for (const auto& d : diags_.all()) n += d.warning ? 0 : 1;
    return n;
}

void JsonReader::error(const std::string& ptr, const std::string& message) {
    diags_.error(make(ptr, index_.value(ptr), message));
}

void JsonReader::errorAtKey(const std::string& ptr, const std::string& message) {
    diags_.error(make(ptr, index_.key(ptr), message));
}

void JsonReader::warning(const std::string& ptr, const std::string& message) {
    diags_.warning(make(ptr, index_.value(ptr), message));
}

void JsonReader::checkKeys(const Json& obj, const std::string& ptr,
                           const std::vector<std::string>& allowed, const std::string& what) {
    if (!obj.is_object()) return;
    for (const auto& item : obj.items()) {
        if (std::find(allowed.begin(), allowed.end(), item.key()) != allowed.end()) continue;
        errorAtKey(jsonPointerChild(ptr, item.key()), "unknown key '" + item.key() + "' in " +
                                                          what + didYouMean(item.key(), allowed) +
                                                          "; valid keys: " + joinNames(allowed));
    }
}

const Json* JsonReader::member(const Json& obj, const std::string& objPtr, const std::string& key,
                               Presence presence, const std::string& expected) {
    if (obj.is_object()) {
        auto it = obj.find(key);
        if (it != obj.end()) return &*it;
    }
    if (presence == Presence::Required && obj.is_object())
        error(jsonPointerChild(objPtr, key),
              "missing required key '" + key + "' (expected " + expected + ")");
    return nullptr;
}

bool JsonReader::isObject(const Json& v, const std::string& ptr, const std::string& expected) {
    if (v.is_object()) return true;
    error(ptr, "expected " + expected + ", got " + describeValue(v));
    return false;
}

bool JsonReader::isArray(const Json& v, const std::string& ptr, const std::string& expected) {
    if (v.is_array()) return true;
    error(ptr, "expected " + expected + ", got " + describeValue(v));
    return false;
}

float JsonReader::number(const Json& v, const std::string& ptr, const NumberRange& range,
                         float fallback) {
    if (!v.is_number()) {
        error(ptr, "expected " + range.describe() + ", got " + describeValue(v));
        return fallback;
    }
    double d = v.get<double>();
    if (!isFiniteFloat(d)) {
        error(ptr, "expected a finite number, got " + v.dump() +
                       " (outside the range of a 32-bit float)");
        return fallback;
    }
    if (!range.contains(d)) {
        error(ptr, "expected " + range.describe() + ", got " + v.dump());
        return fallback;
    }
    return float(d);
}

int64_t JsonReader::integer(const Json& v, const std::string& ptr, int64_t lo, int64_t hi,
                            int64_t fallback) {
    std::string expected = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (!v.is_number()) {
        error(ptr, "expected " + expected + ", got " + describeValue(v));
        return fallback;
    }
    double d = v.get<double>();
    if (v.is_number_float() && (!std::isfinite(d) || d != std::floor(d))) {
        error(ptr, "expected " + expected + ", got " + v.dump() + " (not an integer)");
        return fallback;
    }
    bool inRange;
    int64_t value = 0;
    if (v.is_number_unsigned()) {
        uint64_t u = v.get<uint64_t>();
        inRange = u <= uint64_t(hi) && (lo <= 0 || u >= uint64_t(lo));
        value = int64_t(u);
    } else if (v.is_number_integer()) {
        value = v.get<int64_t>();
        inRange = value >= lo && value <= hi;
    } else {
        inRange = d >= double(lo) && d <= double(hi);
        value = inRange ? int64_t(d) : 0;
    }
    if (!inRange) {
        error(ptr, "expected " + expected + ", got " + v.dump());
        return fallback;
    }
    return value;
}

bool JsonReader::boolean(const Json& v, const std::string& ptr, bool fallback) {
    if (v.is_boolean()) return v.get<bool>();
    error(ptr, "expected true or false, got " + describeValue(v));
    return fallback;
}

std::string JsonReader::string(const Json& v, const std::string& ptr, bool allowEmpty) {
    if (!v.is_string()) {
        error(ptr, "expected a string, got " + describeValue(v));
        return "";
    }
    std::string s = v.get<std::string>();
    if (s.empty() && !allowEmpty) error(ptr, "expected a non-empty string, got \"\"");
    return s;
}

Vec3 JsonReader::vec3(const Json& v, const std::string& ptr, const Vec3& fallback) {
    if (!v.is_array() || v.size() != 3) {
        error(ptr, "expected an array of 3 numbers [x, y, z], got " + describeValue(v));
        return fallback;
    }
    Vec3 r;
    bool ok = true;
    for (size_t i = 0; i < 3; ++i) {
        const Json& c = v[i];
        size_t before = errorCount();
        r[int(i)] = number(c, jsonPointerChild(ptr, i), NumberRange::any(), fallback[int(i)]);
        ok = ok && errorCount() == before;
    }
    return ok ? r : fallback;
}

Vec3 JsonReader::direction(const Json& v, const std::string& ptr, const Vec3& fallback) {
    size_t before = errorCount();
    Vec3 d = vec3(v, ptr, fallback);
    if (errorCount() != before) return fallback;
    if (lengthSqr(d) == 0.0f || !std::isfinite(lengthSqr(d))) {
        error(ptr, "expected a non-zero direction [x, y, z], got " + v.dump());
        return fallback;
    }
    return normalize(d);
}

Rgb JsonReader::rgb(const Json& v, const std::string& ptr, const NumberRange& range,
                    const Rgb& fallback) {
    if (v.is_number()) {
        size_t before = errorCount();
        float g = number(v, ptr, range, 0.0f);
        return errorCount() == before ? Rgb(g) : fallback;
    }
    if (!v.is_array() || v.size() != 3) {
        error(ptr, "expected an RGB colour (one number or [r, g, b], each " + range.describe() +
                       "), got " + describeValue(v));
        return fallback;
    }
    Rgb r;
    bool ok = true;
    for (size_t i = 0; i < 3; ++i) {
        size_t before = errorCount();
        r[int(i)] = number(v[i], jsonPointerChild(ptr, i), range, fallback[int(i)]);
        ok = ok && errorCount() == before;
    }
    return ok ? r : fallback;
}

float JsonReader::getNumber(const Json& obj, const std::string& objPtr, const std::string& key,
                            Presence presence, const NumberRange& range, float fallback) {
    const Json* v = member(obj, objPtr, key, presence, range.describe());
    return v ? number(*v, jsonPointerChild(objPtr, key), range, fallback) : fallback;
}

int64_t JsonReader::getInteger(const Json& obj, const std::string& objPtr, const std::string& key,
                               Presence presence, int64_t lo, int64_t hi, int64_t fallback) {
    const Json* v =
        member(obj, objPtr, key, presence,
               "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v ? integer(*v, jsonPointerChild(objPtr, key), lo, hi, fallback) : fallback;
}

bool JsonReader::getBool(const Json& obj, const std::string& objPtr, const std::string& key,
                         bool fallback) {
    const Json* v = member(obj, objPtr, key, Presence::Optional, "true or false");
    return v ? boolean(*v, jsonPointerChild(objPtr, key), fallback) : fallback;
}

Vec3 JsonReader::getVec3(const Json& obj, const std::string& objPtr, const std::string& key,
                         Presence presence, const Vec3& fallback) {
    const Json* v = member(obj, objPtr, key, presence, "an array of 3 numbers [x, y, z]");
    return v ? vec3(*v, jsonPointerChild(objPtr, key), fallback) : fallback;
}

Vec3 JsonReader::getDirection(const Json& obj, const std::string& objPtr, const std::string& key,
                              Presence presence, const Vec3& fallback) {
    const Json* v = member(obj, objPtr, key, presence, "a non-zero direction [x, y, z]");
    return v ? direction(*v, jsonPointerChild(objPtr, key), fallback) : fallback;
}

Rgb JsonReader::getRgb(const Json& obj, const std::string& objPtr, const std::string& key,
                       Presence presence, const NumberRange& range, const Rgb& fallback) {
    const Json* v = member(obj, objPtr, key, presence,
                           "an RGB colour: one number or [r, g, b], each " + range.describe());
    return v ? rgb(*v, jsonPointerChild(objPtr, key), range, fallback) : fallback;
}

std::string JsonReader::getString(const Json& obj, const std::string& objPtr,
                                  const std::string& key, Presence presence) {
    const Json* v = member(obj, objPtr, key, presence, "a string");
    return v ? string(*v, jsonPointerChild(objPtr, key)) : "";
}

}  // namespace ub
