// Errors in user input (scene files, meshes, images, grids, CLI flags).
// Loaders collect every problem they find in a Diagnostics list and throw one
// InputError at the end, so users see all errors of a file at once. The CLI
// prints them and exits with status 2.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace ub {

struct Diagnostic {
    std::string file;      ///< file the problem is in
    int line = 0;          ///< 1-based line, 0 if unknown
    int column = 0;        ///< 1-based column, 0 if unknown
    std::string where;     ///< JSON path (e.g. "/shapes/2/material") or object name
    std::string message;   ///< what is wrong and what was expected
    bool warning = false;  ///< warnings are printed but do not fail loading
    /// "file:line:col: error: at /path: message"
    std::string format() const;
};

class InputError : public std::runtime_error {
  public:
    explicit InputError(std::vector<Diagnostic> d);
    InputError(const std::string& file, const std::string& message);
    const std::vector<Diagnostic>& diagnostics() const { return diags_; }

  private:
    std::vector<Diagnostic> diags_;
};

/// Accumulates diagnostics; throwIfErrors() throws InputError if any error was added.
class Diagnostics {
  public:
    void error(Diagnostic d) {
        d.warning = false;
        list_.push_back(std::move(d));
        ++errors_;
    }
    void warning(Diagnostic d) {
        d.warning = true;
        list_.push_back(std::move(d));
    }
    bool hasErrors() const { return errors_ > 0; }
    const std::vector<Diagnostic>& all() const { return list_; }
    /// Warnings only (to print after a successful load).
    std::vector<Diagnostic> warnings() const;
    void throwIfErrors() const;

  private:
    std::vector<Diagnostic> list_;
    int errors_ = 0;
};

}  // namespace ub
