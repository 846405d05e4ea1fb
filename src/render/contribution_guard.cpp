#include "render/contribution_guard.h"

namespace ub {

std::string formatRejections(const RejectionCounts& counts) {
    std::string s;
    for (const auto& [technique, n] : counts)
        s += (s.empty() ? "" : ", ") + technique + " " + std::to_string(n);
    return s;
}

std::vector<std::pair<std::string, std::string>> rejectionAttributes(
    const RejectionCounts& counts) {
    std::vector<std::pair<std::string, std::string>> attributes;
    for (const auto& [technique, n] : counts)
        attributes.emplace_back("unibeam.rejected." + technique, std::to_string(n));
    return attributes;
}

}  // namespace ub
