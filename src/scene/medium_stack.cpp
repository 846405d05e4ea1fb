// Medium stack of nested media (rules in medium_stack.h).
#include "scene/medium_stack.h"

namespace ub {

void MediumStack::reset(int32_t globalMediumId) {
    count = 1;
    entries[0] = {-1, globalMediumId, kGlobalPriority};
}

int MediumStack::top() const {
    int best = -1;
    for (int i = 0; i < count; ++i)
        if (best < 0 || entries[i].priority >= entries[best].priority) best = i;
    return best;
}

int32_t MediumStack::mediumId() const {
    int t = top();
    return t < 0 ? -1 : entries[t].mediumId;
}

int32_t MediumStack::priority() const {
    int t = top();
    return t < 0 ? kGlobalPriority : entries[t].priority;
}

bool MediumStack::contains(int32_t shapeId) const {
    for (int i = 0; i < count; ++i)
        if (entries[i].shapeId == shapeId) return true;
    return false;
}

bool MediumStack::push(int32_t shapeId, int32_t mediumId, int32_t priority) {
    if (contains(shapeId)) return true;
    if (count >= kCapacity) return false;
    entries[count++] = {shapeId, mediumId, priority};
    return true;
}

bool MediumStack::pop(int32_t shapeId) {
    for (int i = 0; i < count; ++i) {
        if (entries[i].shapeId != shapeId) continue;
        // Keep the order of the others (ties in priority go to the latest entered).
        for (int j = i + 1; j < count; ++j) entries[j - 1] = entries[j];
        --count;
        return true;
    }
    return false;
}

void MediumStack::setOnly(int32_t shapeId, int32_t mediumId) {
    count = 1;
    entries[0] = {shapeId, mediumId, kGlobalPriority};
}

}  // namespace ub
