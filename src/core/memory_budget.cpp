// MemoryBudget (see memory_budget.h).
#include "core/memory_budget.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>

namespace ub {

namespace {

std::string mb(size_t bytes) {
    char b[32];
    if (bytes < 1024 * 1024)
        std::snprintf(b, sizeof(b), "%.1f KB", double(bytes) / 1024.0);
    else
        std::snprintf(b, sizeof(b), "%.1f MB", double(bytes) / (1024.0 * 1024.0));
    return b;
}

}  // namespace

void MemoryBudget::reserve(size_t bytes, const char* what, const char* advice) {
    const size_t now = used_.fetch_add(bytes, std::memory_order_relaxed) + bytes;
    if (limit_ > 0 && now > limit_) {
        used_.fetch_sub(bytes, std::memory_order_relaxed);
        throw MemoryBudgetError("memory budget exceeded: the " + std::string(what) + " need " +
                                mb(bytes) + " more with " + mb(now - bytes) +
                                " in use, over the limit of " + mb(limit_) +
                                " (--max-memory): " + advice + ", or raise --max-memory");
    }
    size_t p = peak_.load(std::memory_order_relaxed);
    while (now > p && !peak_.compare_exchange_weak(p, now, std::memory_order_relaxed)) {
    }
}

size_t parseMemorySize(const std::string& text) {
    auto bad = [&] {
        return std::invalid_argument("expected a size such as 512M, 8G or 1073741824, got '" +
                                     text + "'");
    };
    size_t i = 0;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.'))
        ++i;
    if (i == 0) throw bad();
    double v = 0;
    try {
        size_t used = 0;
        v = std::stod(text.substr(0, i), &used);
        if (used != i) throw bad();  // e.g. "1.2.3"
    } catch (...) {
        throw bad();
    }
    std::string unit = text.substr(i);
    for (char& c : unit) c = char(std::toupper(static_cast<unsigned char>(c)));
    if (unit.size() >= 2 && unit.compare(unit.size() - 2, 2, "IB") == 0)
        unit.resize(unit.size() - 2);
    else if (!unit.empty() && unit.back() == 'B' && unit.size() > 1)
        unit.pop_back();
    double scale = 1;
    if (unit == "K")
        scale = 1024.0;
    else if (unit == "M")
        scale = 1024.0 * 1024.0;
    else if (unit == "G")
        scale = 1024.0 * 1024.0 * 1024.0;
    else if (unit == "T")
        scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
    else if (!(unit.empty() || unit == "B"))
        throw bad();
    const double bytes = v * scale;
    if (!(bytes >= 1.0) || !std::isfinite(bytes) || bytes > 1e18) throw bad();
    return size_t(bytes);
}

size_t defaultMemoryBudget() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0) return 0;
    return size_t(pages) * size_t(page) / 2;
}

}  // namespace ub
