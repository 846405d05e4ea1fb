#include "core/error.h"

#include <algorithm>
#include <sstream>

namespace ub {

namespace {

// Longest message printed in full: a diagnostic that quotes a 10 MB token from a corrupt file
// would otherwise flood the terminal.
constexpr size_t kMaxPrintedBytes = 2000;

/// Length of the well-formed UTF-8 sequence at s[i] (1-4), or 0 if it is not one.
size_t utf8Length(const std::string& s, size_t i) {
    const auto b = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
    const unsigned char c = b(i);
    size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (n == 0 || i + n > s.size()) return 0;
    for (size_t k = 1; k < n; ++k)
        if ((b(i + k) & 0xC0) != 0x80) return 0;
    // Overlong encodings and code points above U+10FFFF are not well-formed.
    if (n == 2 && c < 0xC2) return 0;
    if (n == 3 && ((c == 0xE0 && b(i + 1) < 0xA0) || (c == 0xED && b(i + 1) > 0x9F))) return 0;
    if (n == 4 && (c > 0xF4 || (c == 0xF0 && b(i + 1) < 0x90) || (c == 0xF4 && b(i + 1) > 0x8F)))
        return 0;
    return n;
}

/// `s` safe to print on a terminal: control characters (but newline and tab) and bytes that are
/// not well-formed UTF-8 become \xNN, and text beyond kMaxPrintedBytes is cut with a note of
/// how much was left out (corrupt files can put anything in a quoted token).
std::string printableText(const std::string& s) {
    std::string out;
    out.reserve(std::min(s.size(), kMaxPrintedBytes) + 16);
    size_t i = 0;
    while (i < s.size() && out.size() < kMaxPrintedBytes) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        const size_t n = utf8Length(s, i);
        if (n == 0 || (n == 1 && ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7F))) {
            static const char* hex = "0123456789abcdef";
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
            ++i;
        } else {
            out.append(s, i, n);
            i += n;
        }
    }
    if (i < s.size()) out += "... (" + std::to_string(s.size() - i) + " more bytes)";
    return out;
}

}  // namespace

std::string Diagnostic::format() const {
    std::ostringstream os;
    os << (file.empty() ? "<input>" : file);
    if (line > 0) {
        os << ':' << line;
        if (column > 0) os << ':' << column;
    }
    os << (warning ? ": warning: " : ": error: ");
    if (!where.empty()) os << "at " << where << ": ";
    os << message;
    return printableText(os.str());
}

static std::string joinDiagnostics(const std::vector<Diagnostic>& d) {
    std::string s;
    for (const auto& x : d) {
        if (!s.empty()) s += '\n';
        s += x.format();
    }
    return s;
}

InputError::InputError(std::vector<Diagnostic> d)
    : std::runtime_error(joinDiagnostics(d)), diags_(std::move(d)) {}

InputError::InputError(const std::string& file, const std::string& message)
    : InputError(std::vector<Diagnostic>{Diagnostic{file, 0, 0, "", message}}) {}

std::vector<Diagnostic> Diagnostics::warnings() const {
    std::vector<Diagnostic> w;
    for (const auto& d : list_)
        if (d.warning) w.push_back(d);
    return w;
}

void Diagnostics::throwIfErrors() const {
    if (!hasErrors()) return;
    std::vector<Diagnostic> e;
    for (const auto& d : list_)
        if (!d.warning) e.push_back(d);
    throw InputError(std::move(e));
}

}  // namespace ub
