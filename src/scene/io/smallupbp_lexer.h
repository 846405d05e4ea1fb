// Whitespace-separated tokens with their file positions, read the way
// SmallUPBP's C reader reads .mtl and .obj.aux files (fscanf "%s" / "%f"):
// a keyword is a token, its numbers are the following tokens (they may even
// continue on the next lines), and a name is the first word of the rest of the
// keyword's line (fgets + sscanf), the remaining words of that line ignored.
#pragma once

#include <string>

#include "core/error.h"

namespace ub {

struct UpbpToken {
    std::string text;
    int line = 0;    ///< 1-based
    int column = 0;  ///< 1-based
};

class UpbpLexer {
  public:
    explicit UpbpLexer(std::string text) : text_(std::move(text)) {}

    /// Next token without consuming it; false at the end of the text.
    bool peek(UpbpToken* token);
    /// Next token, consumed; false at the end of the text.
    bool next(UpbpToken* token);
    /// The rest of the current line (after the last consumed token), trimmed;
    /// moves past the line end. *line/*column: where the rest starts.
    std::string restOfLine(int* line = nullptr, int* column = nullptr);
    /// Line of the last consumed token (or of the position after restOfLine).
    int line() const { return line_; }

  private:
    void skipSpace();
    std::string text_;
    size_t pos_ = 0;
    int line_ = 1;
    size_t lineStart_ = 0;
};

/// Statement reading with diagnostics that name file:line:column. After a bad value the
/// rest of the keyword's line is skipped (one error per statement); a value missing
/// before the next line's keyword leaves that keyword to be read next.
class UpbpReader {
  public:
    UpbpReader(std::string file, std::string text, Diagnostics& diags)
        : file_(std::move(file)), lex_(std::move(text)), diags_(diags) {}

    UpbpLexer& lexer() { return lex_; }
    const std::string& file() const { return file_; }
    void error(int line, int column, const std::string& message);
    void warning(int line, int column, const std::string& message);
    void error(const UpbpToken& at, const std::string& message) {
        error(at.line, at.column, message);
    }
    void warning(const UpbpToken& at, const std::string& message) {
        warning(at.line, at.column, message);
    }
    /// Reads n numbers after keyword kw (named `name` in messages; `what` lists the
    /// values, e.g. "r g b"). False (with an error) if one is missing or not a number.
    bool numbers(const UpbpToken& kw, const std::string& name, int n, const std::string& what,
                 float* out);
    /// Reads one integer after kw.
    bool integer(const UpbpToken& kw, const std::string& name, const std::string& what, int* out);
    /// The first word of the rest of kw's line (SmallUPBP's fgets + sscanf "%s"); extra
    /// words are ignored with a warning. False (error) if the line has no word.
    bool word(const UpbpToken& kw, const std::string& name, const std::string& what,
              UpbpToken* out);

  private:
    std::string file_;
    UpbpLexer lex_;
    Diagnostics& diags_;
};

/// Parses a whole token as a float (as "%f" would, but the token must be only the
/// number). False if the token is not a number or not finite.
bool parseUpbpFloat(const std::string& token, float* value);
/// Parses a whole token as a decimal integer.
bool parseUpbpInt(const std::string& token, int* value);

}  // namespace ub
