#include "core/error.h"

#include <sstream>

namespace ub {

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
    return os.str();
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
