// Strict, typed access to a parsed JSON document with positioned diagnostics.
//
// Every getter validates type and range, and on a problem adds an error that
// names file:line:column (from JsonPositionIndex), the JSON pointer and what
// was expected, then returns a fallback so that reading goes on and all
// problems of a file are reported together. Callers throw at the end
// (Diagnostics::throwIfErrors), so fallbacks never reach a Scene.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/vec.h"
#include "scene/io/json_positions.h"

namespace ub {

/// Keeps the key order of the file (so listings follow the file, e.g. material names).
using Json = nlohmann::ordered_json;

/// Allowed interval of a number; describe() gives the wording used in messages.
struct NumberRange {
    double lo = -1e300, hi = 1e300;
    bool loOpen = false, hiOpen = false;

    static NumberRange any() { return {}; }
    static NumberRange positive() { return {0.0, 1e300, true, false}; }
    static NumberRange nonNegative() { return {0.0, 1e300, false, false}; }
    static NumberRange closed(double a, double b) { return {a, b, false, false}; }
    static NumberRange open(double a, double b) { return {a, b, true, true}; }
    static NumberRange leftOpen(double a, double b) { return {a, b, true, false}; }
    bool contains(double v) const;
    /// "a number > 0", "a number in [0, 1]", ...
    std::string describe() const;
};

enum class Presence { Required, Optional };

/// Levenshtein distance, for "did you mean" hints.
int editDistance(const std::string& a, const std::string& b);
/// " (did you mean 'x'?)" for the closest candidate within distance 2, else "".
std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates);
/// Short form of a number for messages ("%g").
std::string formatNumber(double v);
/// "a, b, c"
std::string joinNames(const std::vector<std::string>& names);

class JsonReader {
  public:
    JsonReader(std::string file, const JsonPositionIndex& index, Diagnostics& diags)
        : file_(std::move(file)), index_(index), diags_(diags) {}

    const std::string& file() const { return file_; }
    Diagnostics& diagnostics() { return diags_; }
    /// Number of errors (not warnings) so far; compare before/after to see if a part failed.
    size_t errorCount() const;

    /// Error located at the value at `ptr` (or its nearest ancestor in the text).
    void error(const std::string& ptr, const std::string& message);
    /// Error located at the key of the member `ptr` (unknown or duplicate keys).
    void errorAtKey(const std::string& ptr, const std::string& message);
    void warning(const std::string& ptr, const std::string& message);

    /// Reports every member of obj whose key is not in `allowed`, listing the valid keys.
    /// `what` names the object in the message ("camera", "diffuse material").
    void checkKeys(const Json& obj, const std::string& ptr, const std::vector<std::string>& allowed,
                   const std::string& what);

    /// The member `key` of obj, or nullptr if absent (an error if required; `expected`
    /// says what the key should hold).
    const Json* member(const Json& obj, const std::string& objPtr, const std::string& key,
                       Presence presence, const std::string& expected);

    // ---- values (ptr is the value's own pointer) ----
    bool isObject(const Json& v, const std::string& ptr, const std::string& expected);
    bool isArray(const Json& v, const std::string& ptr, const std::string& expected);
    float number(const Json& v, const std::string& ptr, const NumberRange& range, float fallback);
    /// Integer in [lo, hi]; non-integral numbers are errors.
    int64_t integer(const Json& v, const std::string& ptr, int64_t lo, int64_t hi,
                    int64_t fallback);
    bool boolean(const Json& v, const std::string& ptr, bool fallback);
    std::string string(const Json& v, const std::string& ptr, bool allowEmpty = false);
    /// [x, y, z] of finite numbers.
    Vec3 vec3(const Json& v, const std::string& ptr, const Vec3& fallback);
    /// Non-zero [x, y, z], returned normalized.
    Vec3 direction(const Json& v, const std::string& ptr, const Vec3& fallback);
    /// A grey value (one number) or [r, g, b]; every component within range.
    Rgb rgb(const Json& v, const std::string& ptr, const NumberRange& range, const Rgb& fallback);

    // ---- members: member() + the value getter; absent optional keys give `fallback` ----
    float getNumber(const Json& obj, const std::string& objPtr, const std::string& key,
                    Presence presence, const NumberRange& range, float fallback);
    int64_t getInteger(const Json& obj, const std::string& objPtr, const std::string& key,
                       Presence presence, int64_t lo, int64_t hi, int64_t fallback);
    bool getBool(const Json& obj, const std::string& objPtr, const std::string& key, bool fallback);
    Vec3 getVec3(const Json& obj, const std::string& objPtr, const std::string& key,
                 Presence presence, const Vec3& fallback);
    Vec3 getDirection(const Json& obj, const std::string& objPtr, const std::string& key,
                      Presence presence, const Vec3& fallback);
    Rgb getRgb(const Json& obj, const std::string& objPtr, const std::string& key,
               Presence presence, const NumberRange& range, const Rgb& fallback);
    /// Returns "" when absent (optional) or wrong.
    std::string getString(const Json& obj, const std::string& objPtr, const std::string& key,
                          Presence presence);

    /// "a number (3.5)", "a string (\"abc\")", "an array", ... for "got ..." in messages.
    static std::string describeValue(const Json& v);

  private:
    Diagnostic make(const std::string& ptr, SourcePos pos, const std::string& message) const;

    std::string file_;
    const JsonPositionIndex& index_;
    Diagnostics& diags_;
};

}  // namespace ub
