// Source positions of the values in a JSON text, by JSON pointer (RFC 6901).
//
// Why this exists: nlohmann-json builds a DOM without source positions, and
// its SAX interface reports positions only for parse errors. Scene errors must
// name the line and column of the offending value (STYLE.md, habit 7), so
// after nlohmann has accepted the text we scan it once more with this small
// scanner, which maps every pointer ("/shapes/2/material") to the position of
// its value and, for object members, of its key. The scanner also reports
// duplicate keys, which nlohmann accepts silently (the last one wins).
//
// The text must already be valid JSON (comments allowed, as parsed with
// ignore_comments = true); on anything else the scanner stops early and the
// positions it has not reached fall back to the nearest ancestor.
#pragma once

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

namespace ub {

struct SourcePos {
    int line = 0;    ///< 1-based, 0 if unknown
    int column = 0;  ///< 1-based, in Unicode code points (a tab counts as one)
};

/// Line/column of a byte offset in text (offsets past the end map to the end).
SourcePos sourcePosOfOffset(const std::string& text, size_t offset);

/// Appends one reference token to a JSON pointer, escaping '~' and '/' (RFC 6901).
std::string jsonPointerChild(const std::string& pointer, const std::string& key);
std::string jsonPointerChild(const std::string& pointer, size_t index);

class JsonPositionIndex {
  public:
    JsonPositionIndex() = default;
    explicit JsonPositionIndex(const std::string& text);

    /// Position of the value at pointer; if the pointer is not in the text (a missing
    /// key), the position of its nearest ancestor that is.
    SourcePos value(const std::string& pointer) const;
    /// Position of the key of an object member (for unknown keys), else value(pointer).
    SourcePos key(const std::string& pointer) const;

    struct Duplicate {
        std::string pointer;  ///< pointer of the repeated member
        SourcePos first;      ///< key position of the first occurrence
        SourcePos again;      ///< key position of the repetition
    };
    const std::vector<Duplicate>& duplicates() const { return duplicates_; }

  private:
    std::unordered_map<std::string, SourcePos> values_, keys_;
    std::vector<Duplicate> duplicates_;
    friend class JsonScanner;
};

}  // namespace ub
