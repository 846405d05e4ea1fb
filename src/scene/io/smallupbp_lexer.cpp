#include "scene/io/smallupbp_lexer.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace ub {

namespace {
bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}
}  // namespace

void UpbpLexer::skipSpace() {
    while (pos_ < text_.size() && isSpace(text_[pos_])) {
        if (text_[pos_] == '\n') {
            ++line_;
            lineStart_ = pos_ + 1;
        }
        ++pos_;
    }
}

bool UpbpLexer::peek(UpbpToken* token) {
    const size_t savePos = pos_, saveStart = lineStart_;
    const int saveLine = line_;
    const bool ok = next(token);
    pos_ = savePos;
    lineStart_ = saveStart;
    line_ = saveLine;
    return ok;
}

bool UpbpLexer::next(UpbpToken* token) {
    skipSpace();
    if (pos_ >= text_.size()) return false;
    size_t end = pos_;
    while (end < text_.size() && !isSpace(text_[end])) ++end;
    token->text = text_.substr(pos_, end - pos_);
    token->line = line_;
    token->column = int(pos_ - lineStart_) + 1;
    pos_ = end;
    return true;
}

std::string UpbpLexer::restOfLine(int* line, int* column) {
    // Skip blanks on the current line only.
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) ++pos_;
    if (line) *line = line_;
    if (column) *column = int(pos_ - lineStart_) + 1;
    size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) end = text_.size();
    std::string rest = text_.substr(pos_, end - pos_);
    while (!rest.empty() && isSpace(rest.back())) rest.pop_back();
    if (end < text_.size()) {
        pos_ = end + 1;
        ++line_;
        lineStart_ = pos_;
    } else {
        pos_ = end;
    }
    return rest;
}

bool parseUpbpFloat(const std::string& token, float* value) {
    if (token.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size()) return false;
    if (!std::isfinite(v) || std::fabs(v) > 3.0e38) return false;
    *value = float(v);
    return true;
}

bool parseUpbpInt(const std::string& token, int* value) {
    if (token.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(token.c_str(), &end, 10);
    if (end != token.c_str() + token.size() || errno == ERANGE || v < -2147483647L ||
        v > 2147483647L)
        return false;
    *value = int(v);
    return true;
}

}  // namespace ub

namespace ub {

void UpbpReader::error(int line, int column, const std::string& message) {
    diags_.error({file_, line, column, "", message});
}

void UpbpReader::warning(int line, int column, const std::string& message) {
    diags_.warning({file_, line, column, "", message});
}

bool UpbpReader::numbers(const UpbpToken& kw, const std::string& name, int n,
                         const std::string& what, float* out) {
    const std::string expected =
        n == 1 ? "1 number (" + what + ")" : std::to_string(n) + " numbers (" + what + ")";
    for (int i = 0; i < n; ++i) {
        UpbpToken t;
        if (!lex_.peek(&t)) {
            error(kw, "'" + name + "' expects " + expected + " but the file ends after " +
                          std::to_string(i));
            return false;
        }
        if (parseUpbpFloat(t.text, &out[i])) {
            lex_.next(&t);
            continue;
        }
        if (t.line == kw.line) {
            error(t, "'" + t.text + "' is not a number: '" + name + "' expects " + expected);
            lex_.restOfLine();
        } else {
            error(kw, "missing value: '" + name + "' expects " + expected + ", found " +
                          std::to_string(i) + " before '" + t.text + "' on line " +
                          std::to_string(t.line));
        }
        return false;
    }
    return true;
}

bool UpbpReader::integer(const UpbpToken& kw, const std::string& name, const std::string& what,
                         int* out) {
    UpbpToken t;
    if (!lex_.peek(&t)) {
        error(kw, "'" + name + "' expects an integer (" + what + ") but the file ends");
        return false;
    }
    if (parseUpbpInt(t.text, out)) {
        lex_.next(&t);
        return true;
    }
    if (t.line == kw.line) {
        error(t, "'" + t.text + "' is not an integer: '" + name + "' expects an integer (" + what +
                     ")");
        lex_.restOfLine();
    } else {
        error(kw, "missing value: '" + name + "' expects an integer (" + what +
                      "), found nothing before '" + t.text + "' on line " + std::to_string(t.line));
    }
    return false;
}

bool UpbpReader::word(const UpbpToken& kw, const std::string& name, const std::string& what,
                      UpbpToken* out) {
    int line = 0, column = 0;
    std::string rest = lex_.restOfLine(&line, &column);
    if (rest.empty()) {
        error(kw, "missing value: '" + name + "' expects " + what + " on the same line");
        return false;
    }
    size_t end = rest.find_first_of(" \t");
    out->text = rest.substr(0, end);
    out->line = line;
    out->column = column;
    if (end != std::string::npos) {
        size_t extra = rest.find_first_not_of(" \t", end);
        if (extra != std::string::npos)
            warning(line, column + int(extra),
                    "ignored '" + rest.substr(extra) + "' after the " + what + " of '" + name +
                        "' (SmallUPBP reads only the first word)");
    }
    return true;
}

}  // namespace ub
