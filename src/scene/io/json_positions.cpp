#include "scene/io/json_positions.h"

#include <algorithm>
#include <cstdint>

namespace ub {

SourcePos sourcePosOfOffset(const std::string& text, size_t offset) {
    offset = std::min(offset, text.size());
    SourcePos p{1, 1};
    for (size_t i = 0; i < offset; ++i) {
        unsigned char c = static_cast<unsigned char>(text[i]);
        if (c == '\n') {
            ++p.line;
            p.column = 1;
        } else if ((c & 0xC0) != 0x80) {  // count code points, not UTF-8 continuation bytes
            ++p.column;
        }
    }
    return p;
}

std::string jsonPointerChild(const std::string& pointer, const std::string& key) {
    std::string r = pointer + '/';
    for (char c : key) {
        if (c == '~')
            r += "~0";
        else if (c == '/')
            r += "~1";
        else
            r += c;
    }
    return r;
}

std::string jsonPointerChild(const std::string& pointer, size_t index) {
    return pointer + '/' + std::to_string(index);
}

// Recursive-descent walk over a JSON text that nlohmann already accepted.
class JsonScanner {
  public:
    JsonScanner(const std::string& text, JsonPositionIndex& index) : s_(text), idx_(index) {
        // Line starts, so that offset -> line:column is a binary search plus a short count.
        lineStarts_.push_back(0);
        for (size_t i = 0; i < s_.size(); ++i)
            if (s_[i] == '\n') lineStarts_.push_back(i + 1);
    }

    void run() {
        skipSpace();
        if (i_ < s_.size()) value("");
    }

  private:
    const std::string& s_;
    JsonPositionIndex& idx_;
    std::vector<size_t> lineStarts_;
    size_t i_ = 0;
    bool failed_ = false;
    int depth_ = 0;
    static constexpr int kMaxDepth = 256;

    SourcePos pos(size_t offset) const {
        auto it = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), offset);
        size_t line = size_t(it - lineStarts_.begin());  // 1-based
        SourcePos p{int(line), 1};
        for (size_t k = lineStarts_[line - 1]; k < offset && k < s_.size(); ++k)
            if ((static_cast<unsigned char>(s_[k]) & 0xC0) != 0x80) ++p.column;
        return p;
    }

    void skipSpace() {
        while (i_ < s_.size()) {
            char c = s_[i_];
            if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
                ++i_;
            } else if (c == '/' && i_ + 1 < s_.size() && s_[i_ + 1] == '/') {
                while (i_ < s_.size() && s_[i_] != '\n') ++i_;
            } else if (c == '/' && i_ + 1 < s_.size() && s_[i_ + 1] == '*') {
                size_t end = s_.find("*/", i_ + 2);
                i_ = end == std::string::npos ? s_.size() : end + 2;
            } else {
                break;
            }
        }
    }

    static void appendUtf8(std::string& out, uint32_t cp) {
        if (cp < 0x80) {
            out += char(cp);
        } else if (cp < 0x800) {
            out += char(0xC0 | (cp >> 6));
            out += char(0x80 | (cp & 0x3F));
        } else if (cp < 0x10000) {
            out += char(0xE0 | (cp >> 12));
            out += char(0x80 | ((cp >> 6) & 0x3F));
            out += char(0x80 | (cp & 0x3F));
        } else {
            out += char(0xF0 | (cp >> 18));
            out += char(0x80 | ((cp >> 12) & 0x3F));
            out += char(0x80 | ((cp >> 6) & 0x3F));
            out += char(0x80 | (cp & 0x3F));
        }
    }

    uint32_t hex4() {
        uint32_t v = 0;
        for (int k = 0; k < 4 && i_ < s_.size(); ++k, ++i_) {
            char c = s_[i_];
            v <<= 4;
            if (c >= '0' && c <= '9')
                v |= uint32_t(c - '0');
            else if (c >= 'a' && c <= 'f')
                v |= uint32_t(c - 'a' + 10);
            else if (c >= 'A' && c <= 'F')
                v |= uint32_t(c - 'A' + 10);
        }
        return v;
    }

    /// Reads a string starting at the opening quote; returns its decoded value
    /// (so that keys match the ones nlohmann stores).
    std::string string() {
        std::string out;
        ++i_;  // opening quote
        while (i_ < s_.size() && s_[i_] != '"') {
            char c = s_[i_++];
            if (c != '\\') {
                out += c;
                continue;
            }
            if (i_ >= s_.size()) break;
            char e = s_[i_++];
            switch (e) {
                case 'b':
                    out += '\b';
                    break;
                case 'f':
                    out += '\f';
                    break;
                case 'n':
                    out += '\n';
                    break;
                case 'r':
                    out += '\r';
                    break;
                case 't':
                    out += '\t';
                    break;
                case 'u': {
                    uint32_t cp = hex4();
                    if (cp >= 0xD800 && cp < 0xDC00 && i_ + 1 < s_.size() && s_[i_] == '\\' &&
                        s_[i_ + 1] == 'u') {
                        i_ += 2;
                        uint32_t lo = hex4();
                        cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
                    }
                    appendUtf8(out, cp);
                    break;
                }
                default:
                    out += e;
                    break;  // \" \\ \/
            }
        }
        ++i_;  // closing quote
        return out;
    }

    void value(const std::string& ptr) {
        // Deeper nesting than any scene needs: stop (positions below fall back to the
        // ancestors) rather than risk the stack on a hostile file.
        if (failed_ || i_ >= s_.size() || depth_ > kMaxDepth) {
            failed_ = true;
            return;
        }
        struct DepthGuard {
            int& d;
            explicit DepthGuard(int& x) : d(x) { ++d; }
            ~DepthGuard() { --d; }
        } guard(depth_);
        idx_.values_[ptr] = pos(i_);
        char c = s_[i_];
        if (c == '{') {
            object(ptr);
        } else if (c == '[') {
            array(ptr);
        } else if (c == '"') {
            string();
        } else {
            // number or literal: runs until a delimiter
            while (i_ < s_.size() && s_[i_] != ',' && s_[i_] != '}' && s_[i_] != ']' &&
                   s_[i_] != ' ' && s_[i_] != '\t' && s_[i_] != '\n' && s_[i_] != '\r' &&
                   s_[i_] != '/')
                ++i_;
        }
    }

    void object(const std::string& ptr) {
        ++i_;  // '{'
        std::unordered_map<std::string, SourcePos> seen;
        skipSpace();
        if (i_ < s_.size() && s_[i_] == '}') {
            ++i_;
            return;
        }
        while (!failed_ && i_ < s_.size()) {
            skipSpace();
            if (i_ >= s_.size() || s_[i_] != '"') {
                failed_ = true;
                return;
            }
            SourcePos keyPos = pos(i_);
            std::string key = string();
            std::string child = jsonPointerChild(ptr, key);
            auto prev = seen.find(key);
            if (prev != seen.end()) {
                idx_.duplicates_.push_back({child, prev->second, keyPos});
            } else {
                seen.emplace(key, keyPos);
            }
            idx_.keys_[child] = keyPos;
            skipSpace();
            if (i_ >= s_.size() || s_[i_] != ':') {
                failed_ = true;
                return;
            }
            ++i_;
            skipSpace();
            value(child);
            skipSpace();
            if (i_ < s_.size() && s_[i_] == ',') {
                ++i_;
                continue;
            }
            if (i_ < s_.size() && s_[i_] == '}') {
                ++i_;
                return;
            }
            failed_ = true;
        }
    }

    void array(const std::string& ptr) {
        ++i_;  // '['
        skipSpace();
        if (i_ < s_.size() && s_[i_] == ']') {
            ++i_;
            return;
        }
        for (size_t n = 0; !failed_ && i_ < s_.size(); ++n) {
            skipSpace();
            value(jsonPointerChild(ptr, n));
            skipSpace();
            if (i_ < s_.size() && s_[i_] == ',') {
                ++i_;
                continue;
            }
            if (i_ < s_.size() && s_[i_] == ']') {
                ++i_;
                return;
            }
            failed_ = true;
        }
    }
};

JsonPositionIndex::JsonPositionIndex(const std::string& text) {
    JsonScanner scanner(text, *this);
    scanner.run();
}

SourcePos JsonPositionIndex::value(const std::string& pointer) const {
    std::string p = pointer;
    for (;;) {
        auto it = values_.find(p);
        if (it != values_.end()) return it->second;
        if (p.empty()) return {};
        size_t slash = p.rfind('/');
        p.erase(slash == std::string::npos ? 0 : slash);
    }
}

SourcePos JsonPositionIndex::key(const std::string& pointer) const {
    auto it = keys_.find(pointer);
    return it != keys_.end() ? it->second : value(pointer);
}

}  // namespace ub
