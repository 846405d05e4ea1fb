// Nested participating media: which medium a point of a path is in.
//
// Semantics (Mitsuba's interior media + SmallUPBP's priorities; Schmidt and
// Budge 2002, "Simple Nested Dielectrics in Ray Traced Images"):
//  * The scene has a global medium (Scene::globalMediumId, -1 = vacuum) that
//    fills everything outside every boundary; the camera starts in it unless it
//    is inside boundaries (Scene::mediumStackAt traces to infinity and counts
//    crossings).
//  * A closed mesh or a sphere may declare itself a medium *boundary*: its
//    interior medium (or -1, explicitly vacuum), an integer priority, and
//    whether it is *imaginary* (it changes the medium but never scatters,
//    refracts or emits, like Mitsuba's null BSDF). A shape that declares
//    nothing never changes the medium.
//  * A path carries a MediumStack of the boundaries it is inside, the global
//    medium at the bottom (priority kGlobalPriority, below every user
//    priority). The current medium is the entry of highest priority (among
//    equal priorities, the one entered last).
//  * Crossing a boundary S at a hit with geometric normal n along direction d:
//    entering = dot(d, n) < 0 (normals point out of closed shapes). Entering
//    pushes S; leaving removes S's entry wherever it is in the stack (it need
//    not be the top). Entering a shape already on the stack, or leaving one
//    that is not on it (both only after numerical leaks), changes nothing.
//  * A hit on boundary S is *real* (a surface vertex: BSDF, emission) iff S is
//    not imaginary and priority(S) >= priority of the current medium, both
//    taken before the crossing. Otherwise it is *skipped*: the stack is
//    updated and the ray goes on as if the surface were not there. Example:
//    a glass (priority 1, interior vacuum) holding milk (priority 2) whose mesh
//    overlaps the glass wall: from inside the milk the inner wall of the glass
//    is skipped, so the milk-glass interface is the milk's surface only.
//    Shapes that are not boundaries are always real and never touch the stack.
//  * At a real hit on a boundary the stack is the one on the incoming side; a
//    continuation (or shadow ray) that leaves on the other side of the
//    surface crosses S (Scene::crossSurface).
// Mitsuba 3's rule (RenderSettings::mediumTransitions = kShapeSides) uses the
// same type with a single entry (setOnly): crossing S sets the medium to S's
// interior (entering) or exterior (leaving) medium, forgetting the others.
// Overflow: pushing onto a full stack fails (push returns false) and callers
// end the path; Scene validation rejects scenes in which more than
// kCapacity - 1 boundaries can overlap, so a valid scene never overflows.
//
// Flat data (int32 fields, no pointers), so the stack can be stored in light
// and camera vertices and copied to OpenCL devices.
#pragma once

#include <cstdint>

namespace ub {

struct MediumStackEntry {
    int32_t shapeId;   ///< boundary shape, -1 for the global medium
    int32_t mediumId;  ///< index into Scene::media, -1 = vacuum
    int32_t priority;
};

struct MediumStack {
    static constexpr int kCapacity = 16;
    static constexpr int32_t kGlobalPriority = INT32_MIN;

    int32_t count = 0;
    MediumStackEntry entries[kCapacity];

    /// Only the global medium.
    void reset(int32_t globalMediumId);
    /// Index of the current (highest-priority, latest among ties) entry; -1 if empty.
    int top() const;
    /// Current medium (-1 vacuum) and its priority.
    int32_t mediumId() const;
    int32_t priority() const;
    bool contains(int32_t shapeId) const;
    /// Enters boundary shapeId. No-op (true) if it is already inside; false if full.
    bool push(int32_t shapeId, int32_t mediumId, int32_t priority);
    /// Leaves boundary shapeId; false if it was not on the stack (no-op).
    bool pop(int32_t shapeId);
    /// Replaces the whole stack by one entry of the lowest priority: the medium mediumId set
    /// by crossing shapeId (MediumTransitions::kShapeSides, Mitsuba 3's rule; any boundary
    /// then has a priority >= the current one, so none is skipped).
    void setOnly(int32_t shapeId, int32_t mediumId);
};

static_assert(sizeof(MediumStackEntry) == 12, "flat layout");
static_assert(sizeof(MediumStack) == 4 + 12 * MediumStack::kCapacity, "flat layout");

}  // namespace ub
