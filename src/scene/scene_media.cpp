// Scene queries for participating media: validation of medium boundaries,
// the medium stack at a point, tracing through imaginary and skipped
// boundaries, and transmittance-only shadow rays (rules in
// scene/medium_stack.h, data in scene/medium_trace.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/rng.h"
#include "scene/scene.h"

namespace ub {

namespace {

std::string fmtPoint(const Vec3& p) {
    char buf[96];
    std::snprintf(buf, sizeof(buf), "(%g, %g, %g)", double(p.x), double(p.y), double(p.z));
    return buf;
}

bool finiteNonNegative(const Rgb& c) {
    return isFinite(c) && minComponent(c) >= 0.0f;
}

bool boundsOverlap(const Bounds3& a, const Bounds3& b) {
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
           a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
}

/// Whether two boundary shapes can overlap: exact for two spheres, bounding boxes otherwise
/// (conservative: boxes that overlap may hold shapes that do not).
bool mayOverlap(const ShapeInfo& a, const ShapeInfo& b) {
    if (!boundsOverlap(a.bounds, b.bounds)) return false;
    if (a.isSphere && b.isSphere) {
        Vec3 ca = a.bounds.center(), cb = b.bounds.center();
        float ra = 0.5f * (a.bounds.hi.x - a.bounds.lo.x),
              rb = 0.5f * (b.bounds.hi.x - b.bounds.lo.x);
        return length(ca - cb) < ra + rb;
    }
    return true;
}

uint64_t edgeKey(uint32_t a, uint32_t b) {
    return (uint64_t(a) << 32) | b;
}

/// Mesh closedness check: after welding vertices by exact position, every directed edge
/// (a, b) of a triangle must occur exactly once and its reverse (b, a) exactly once, i.e.
/// every edge is shared by exactly two triangles of opposite orientation (a closed,
/// consistently oriented 2-manifold surface). Returns the number of bad edges and the first.
size_t countBadEdges(const Scene& scene, uint32_t shapeId, size_t triangleCount, Vec3* badA,
                     Vec3* badB) {
    struct PosHash {
        size_t operator()(const Vec3& p) const {
            uint32_t b[3];
            std::memcpy(&b[0], &p.x, 4);
            std::memcpy(&b[1], &p.y, 4);
            std::memcpy(&b[2], &p.z, 4);
            return size_t(mix64(b[0] ^ (uint64_t(b[1]) << 21) ^ (uint64_t(b[2]) << 42)));
        }
    };
    struct PosEq {
        bool operator()(const Vec3& a, const Vec3& b) const {
            return a.x == b.x && a.y == b.y && a.z == b.z;
        }
    };
    std::unordered_map<Vec3, uint32_t, PosHash, PosEq> welded;
    std::vector<Vec3> positions;
    std::unordered_map<uint64_t, int> directed;
    auto weld = [&](const Vec3& p) {
        auto it = welded.find(p);
        if (it != welded.end()) return it->second;
        uint32_t id = uint32_t(positions.size());
        welded.emplace(p, id);
        positions.push_back(p);
        return id;
    };
    for (size_t t = 0; t < triangleCount; ++t) {
        Vec3 p[3];
        scene.meshTriangle(shapeId, uint32_t(t), p);
        uint32_t v[3] = {weld(p[0]), weld(p[1]), weld(p[2])};
        for (int e = 0; e < 3; ++e) ++directed[edgeKey(v[e], v[(e + 1) % 3])];
    }
    size_t bad = 0;
    for (const auto& [key, n] : directed) {
        uint32_t a = uint32_t(key >> 32), b = uint32_t(key & 0xffffffffu);
        auto rev = directed.find(edgeKey(b, a));
        int nRev = rev == directed.end() ? 0 : rev->second;
        if (n == 1 && nRev == 1) continue;
        if (bad++ == 0) *badA = positions[a], *badB = positions[b];
    }
    return bad;
}

// Free-flight pdf products over a segment chain (medium_trace.h).
struct ChainPdfs {
    Rgb T{1.0f};
    float probPass = 1.0f;        // prod over all segments
    float passBeforeLast = 1.0f;  // prod over all but the last
    float passAfterFirst = 1.0f;  // prod over all but the first
    float fwdLast = 0.0f, revFirst = 0.0f;
    int count = 0;

    void add(const Scene& scene, int mediumId, const Vec3& org, const Vec3& dir, float len) {
        MediumSegment seg;
        seg.length = len;
        if (mediumId >= 0) seg = evalMediumSegment(scene.media[size_t(mediumId)], org, dir, len);
        const float pass = seg.probPass();
        T *= seg.transmittance;
        passBeforeLast = probPass;
        if (count > 0)
            passAfterFirst *= pass;
        else
            revFirst = seg.pdfScatterRevL();
        probPass *= pass;
        fwdLast = seg.pdfScatterFwdL();
        ++count;
    }
    MediumShadow result() const {
        MediumShadow s;
        s.transmittance = T;
        s.probPass = probPass;
        s.pdfScatterFwdL = passBeforeLast * fwdLast;
        s.pdfScatterRevL = revFirst * passAfterFirst;
        s.segmentCount = count;
        return s;
    }
};

MediumShadow blockedShadow() {
    MediumShadow s;
    s.blocked = true;
    s.transmittance = Rgb(0.0f);
    s.probPass = 0.0f;
    return s;
}

}  // namespace

std::vector<MediumIssue> Scene::mediumIssues() const {
    std::vector<MediumIssue> issues;
    auto add = [&](int shapeId, int mediumId, const std::string& msg) {
        issues.push_back({shapeId, mediumId, msg});
    };
    for (size_t i = 0; i < media.size(); ++i) {
        const Medium& m = media[i];
        const std::string name = "medium '" + (i < mediumNames.size() ? mediumNames[i] : "") + "'";
        if (!(std::fabs(m.g) < 1.0f))
            add(-1, int(i),
                name + ": the Henyey-Greenstein g must lie in (-1, 1), got " + std::to_string(m.g));
        if (m.albedoGrid && m.type != MediumType::kGrid)
            add(-1, int(i), name + ": an albedo grid needs a heterogeneous (grid) medium");
        if (m.type == MediumType::kHomogeneous) {
            if (!finiteNonNegative(m.sigmaA) || !finiteNonNegative(m.sigmaS) ||
                !finiteNonNegative(m.Le))
                add(-1, int(i),
                    name +
                        ": negative or non-finite coefficients (sigma_a, "
                        "sigma_s and emission must be finite and >= 0)");
        } else if (!m.grid || !(m.densityScale >= 0.0f) || !std::isfinite(m.densityScale) ||
                   !finiteNonNegative(m.albedo) || maxComponent(m.albedo) > 1.0f) {
            add(-1, int(i),
                name +
                    ": needs a grid, a finite density scale >= 0 and an albedo "
                    "in [0, 1]");
        }
    }
    if (globalMediumId < -1 || globalMediumId >= int(media.size()))
        add(-1, -1, "the global medium id " + std::to_string(globalMediumId) + " is out of range");

    std::vector<uint32_t> boundaries;
    for (size_t s = 0; s < shapes.size(); ++s) {
        const ShapeInfo& sh = shapes[s];
        if (!sh.isMediumBoundary) continue;
        boundaries.push_back(uint32_t(s));
        const std::string name = "shape '" + sh.name + "'";
        if (sh.interiorMediumId < -1 || sh.interiorMediumId >= int(media.size()))
            add(int(s), -1,
                name + ": interior medium id " + std::to_string(sh.interiorMediumId) +
                    " is out of range");
        if (sh.exteriorMediumId < -1 || sh.exteriorMediumId >= int(media.size()))
            add(int(s), -1,
                name + ": exterior medium id " + std::to_string(sh.exteriorMediumId) +
                    " is out of range");
        if (sh.exteriorMediumId >= 0 &&
            settings.mediumTransitions != MediumTransitions::kShapeSides)
            add(int(s), -1,
                name +
                    " has an exterior medium, which only Mitsuba's medium transitions use "
                    "(the priority stack derives the outside medium from the boundaries "
                    "around the shape)");
        if (sh.imaginary && sh.lightId >= 0)
            add(int(s), -1, name + " is an imaginary medium boundary and cannot emit light");
        if (sh.isSdfGrid) {
            add(int(s), -1, name + " is an sdfgrid, which cannot bound a medium");
        } else if (!sh.isSphere) {
            Vec3 a, b;
            size_t bad = countBadEdges(*this, uint32_t(s), sh.triangleCount, &a, &b);
            // Mitsuba's transitions are local to each crossing (the side of the face), so an
            // open mesh is defined there, as in Mitsuba: a path that leaves through a gap keeps
            // the interior medium. The priority stack needs closed boundaries.
            const bool local = settings.mediumTransitions == MediumTransitions::kShapeSides;
            if (bad > 0) {
                add(int(s), -1,
                    name +
                        " is a medium boundary but its mesh is not closed: " + std::to_string(bad) +
                        " edges are not shared by exactly two triangles of opposite orientation "
                        "(first: " +
                        fmtPoint(a) + " - " + fmtPoint(b) +
                        (local ? "); as in Mitsuba, a path that leaves through a gap keeps its "
                                 "interior medium"
                               : "); a medium boundary must be a closed, consistently "
                                 "oriented surface"));
                issues.back().warning = local;
            }
        }
    }
    // Mitsuba's transitions keep one medium and ignore priorities: overlaps are allowed.
    if (settings.mediumTransitions == MediumTransitions::kShapeSides) return issues;
    // Conflicting priorities: overlapping boundaries of equal priority and different media
    // would make the current medium depend on the order in which a path enters them.
    int maxOverlap = 0;
    for (size_t i = 0; i < boundaries.size(); ++i) {
        const ShapeInfo& a = shapes[boundaries[i]];
        int overlap = 1;
        for (size_t j = 0; j < boundaries.size(); ++j) {
            if (j == i) continue;
            const ShapeInfo& b = shapes[boundaries[j]];
            if (!mayOverlap(a, b)) continue;
            ++overlap;
            if (j > i && a.mediumPriority == b.mediumPriority &&
                a.interiorMediumId != b.interiorMediumId)
                add(int(boundaries[j]), -1,
                    "conflicting medium priorities: shapes '" + a.name + "' and '" + b.name +
                        "' overlap, have the same priority " + std::to_string(a.mediumPriority) +
                        " and different interior media (give the one that should win inside "
                        "the overlap a higher priority)");
        }
        maxOverlap = std::max(maxOverlap, overlap);
    }
    if (maxOverlap + 1 > MediumStack::kCapacity)
        add(-1, -1,
            "up to " + std::to_string(maxOverlap) +
                " medium boundaries overlap (bounding boxes); at most " +
                std::to_string(MediumStack::kCapacity - 1) + " can be nested");
    return issues;
}

bool Scene::hasMedia() const {
    if (globalMediumId >= 0) return true;
    for (const ShapeInfo& s : shapes)
        if (s.isMediumBoundary) return true;
    return false;
}

bool Scene::crossBoundary(uint32_t shapeId, const Vec3& geoNormal, const Vec3& dir,
                          MediumStack* stack) const {
    if (!shapes[shapeId].isMediumBoundary) return true;
    return applyCrossing(shapeId, dot(dir, geoNormal) < 0.0f, stack);
}

bool Scene::applyCrossing(uint32_t shapeId, bool entering, MediumStack* stack) const {
    const ShapeInfo& s = shapes[shapeId];
    if (settings.mediumTransitions == MediumTransitions::kShapeSides) {
        // Mitsuba 3: the medium on the side of the shape the path goes to.
        stack->setOnly(int32_t(shapeId), entering ? s.interiorMediumId : s.exteriorMediumId);
        return true;
    }
    if (entering) return stack->push(int32_t(shapeId), s.interiorMediumId, s.mediumPriority);
    stack->pop(int32_t(shapeId));
    return true;
}

bool Scene::crossSurface(const Hit& hit, const Vec3& dirFix, const Vec3& dirGen,
                         MediumStack* stack) const {
    const bool fixOutside = dot(dirFix, hit.geoNormal) > 0.0f;
    const bool genOutside = dot(dirGen, hit.geoNormal) > 0.0f;
    // Mitsuba 3 sets the medium of dirGen's side at every interaction with a boundary, a
    // reflection included (the path may have reached the surface in another medium).
    if (settings.mediumTransitions == MediumTransitions::kShapeSides &&
        shapes[hit.shapeId].isMediumBoundary)
        return applyCrossing(hit.shapeId, !genOutside, stack);
    if (fixOutside == genOutside) return true;  // reflection: same side, same media
    return crossBoundary(hit.shapeId, hit.geoNormal, dirGen, stack);
}

MediumStack Scene::mediumStackAt(const Vec3& p) const {
    MediumStack stack;
    stack.reset(globalMediumId);
    bool anyBoundary = false;
    for (const ShapeInfo& s : shapes) anyBoundary |= s.isMediumBoundary;
    if (!anyBoundary) return stack;
    if (settings.mediumTransitions == MediumTransitions::kShapeSides)
        return mediumStackAtShapeSides(p);
    // Three rays in generic directions; a boundary contains p if it does along at least two
    // (a ray grazing an edge or a tangent cannot then flip the answer). Along one ray,
    // p is inside S if the ray leaves S once more than it enters it.
    const Vec3 dirs[3] = {normalize(Vec3(0.5773f, 0.6181f, 0.5331f)),
                          normalize(Vec3(-0.4131f, 0.3167f, -0.8537f)),
                          normalize(Vec3(0.2719f, -0.9146f, 0.2993f))};
    std::vector<int> votes(shapes.size(), 0);
    std::vector<float> nearestExit(shapes.size(), 0.0f);
    for (const Vec3& dir : dirs) {
        std::vector<int> net(shapes.size(), 0);
        std::vector<float> firstExit(shapes.size(), -1.0f);
        Ray r;
        r.org = p;
        r.dir = dir;
        float travelled = 0.0f;
        for (int guard = 0; guard < 100000; ++guard) {
            Hit h;
            if (!intersect(r, &h)) break;
            travelled += h.dist;
            if (shapes[h.shapeId].isMediumBoundary) {
                const bool leaving = dot(dir, h.geoNormal) > 0.0f;
                net[h.shapeId] += leaving ? 1 : -1;
                if (leaving && firstExit[h.shapeId] < 0.0f) firstExit[h.shapeId] = travelled;
            }
            r = spawnRay(h, dir);
        }
        for (size_t s = 0; s < shapes.size(); ++s)
            if (net[s] > 0) {
                ++votes[s];
                nearestExit[s] = std::max(nearestExit[s], firstExit[s]);
            }
    }
    // Push the outermost first: walking from infinity to p, the boundary whose exit is
    // farthest from p was entered first (ties in priority go to the one entered last).
    std::vector<uint32_t> inside;
    for (size_t s = 0; s < shapes.size(); ++s)
        if (votes[s] >= 2) inside.push_back(uint32_t(s));
    std::sort(inside.begin(), inside.end(),
              [&](uint32_t a, uint32_t b) { return nearestExit[a] > nearestExit[b]; });
    for (uint32_t s : inside)
        if (!stack.push(int32_t(s), shapes[s].interiorMediumId, shapes[s].mediumPriority)) break;
    return stack;
}

void Scene::traceMedia(const Ray& ray, MediumStack* stack, MediumTrace* trace, Hit* hit,
                       Rng* lookahead) const {
    trace->count = 0;
    trace->hitSurface = false;
    trace->overflow = false;
    trace->truncated = false;
    trace->distance = 0.0f;
    Ray r = ray;
    Vec3 segStart = ray.org + ray.dir * ray.tMin;
    for (;;) {
        if (trace->count >= MediumTrace::kMaxSegments) {
            trace->overflow = true;
            return;
        }
        MediumTraceSegment& seg = trace->segments[trace->count];
        seg.origin = segStart;
        seg.mediumId = stack->mediumId();
        seg.crossingShape = -1;
        seg.crossingEntering = 0;
        // Where free-flight sampling will stop in this segment, if it is homogeneous.
        float cut = kInf;
        if (lookahead && seg.mediumId >= 0) {
            const float uChannel = lookahead->uniform(), uDistance = lookahead->uniform();
            const Medium& m = media[size_t(seg.mediumId)];
            if (m.type == MediumType::kHomogeneous)
                cut = homogeneousFlightDistance(m, uChannel, uDistance);
        }
        Ray rc = r;
        if (cut < 0.5f * kMediumFarDistance) {
            // Past the sampled distance by more than the distance between r's origin and
            // the segment start (a crossing's offset) and the rounding of either: a hit up
            // to there is found as without the cut, and no hit means the segment is longer.
            const float margin = 4.0f * rayOffsetLength(segStart) + 1e-5f * cut;
            rc.tMax = std::min(r.tMax, r.tMin + cut + margin);
        }
        Hit h;
        if (!intersectNearest(rc, &h)) {
            // Escaped, or cut: then sampling stops in this segment.
            seg.length = kMediumFarDistance;
            trace->distance = kInf;
            trace->truncated = rc.tMax < r.tMax;
            ++trace->count;
            return;
        }
        ++trace->count;
        // A crossing is completed now (its point and normal spawn the next ray); a real hit
        // where the path reaches it, since the path may scatter before. Its segment ends at
        // the ray's point (h.pos before completion), which differs from the triangle's point
        // by the rounding of the two.
        const bool real = realFor(h.shapeId, stack->priority());
        if (!real) completeHit(rc, &h);
        seg.length = length(h.pos - segStart);
        trace->distance += seg.length;
        if (real) {
            trace->hitSurface = true;
            trace->hitRay = rc;
            *hit = h;
            return;
        }
        seg.crossingShape = int32_t(h.shapeId);
        seg.crossingEntering = dot(r.dir, h.geoNormal) < 0.0f ? 1 : 0;
        if (!crossBoundary(h.shapeId, h.geoNormal, r.dir, stack)) {
            trace->overflow = true;
            return;
        }
        segStart = h.pos;
        r = spawnRay(h, ray.dir);
    }
}

void Scene::replayCrossings(const MediumTrace& trace, int k, MediumStack* stack) const {
    for (int j = 0; j < k && j < trace.count; ++j) {
        const MediumTraceSegment& seg = trace.segments[j];
        if (seg.crossingShape < 0) continue;
        applyCrossing(uint32_t(seg.crossingShape), seg.crossingEntering != 0, stack);
    }
}

MediumStack Scene::mediumStackAtShapeSides(const Vec3& p) const {
    // The medium a path arriving at p from the nearest boundary along a ray would carry: the
    // side of that boundary p is on. Three generic directions, majority vote (the first
    // ray's answer if all differ), so that a ray grazing an edge cannot decide alone. In a
    // scene whose boundaries overlap the medium at a point can depend on the path (Mitsuba
    // 3 has the same ambiguity; its sensors and emitters name their medium instead).
    const Vec3 dirs[3] = {normalize(Vec3(0.5773f, 0.6181f, 0.5331f)),
                          normalize(Vec3(-0.4131f, 0.3167f, -0.8537f)),
                          normalize(Vec3(0.2719f, -0.9146f, 0.2993f))};
    MediumStack found[3];
    for (int i = 0; i < 3; ++i) {
        found[i].reset(globalMediumId);
        Ray r;
        r.org = p;
        r.dir = dirs[i];
        for (int guard = 0; guard < 100000; ++guard) {
            Hit h;
            if (!intersect(r, &h)) break;
            if (shapes[h.shapeId].isMediumBoundary) {
                // Leaving the shape along dirs[i]: p is inside it.
                const ShapeInfo& s = shapes[h.shapeId];
                const bool inside = dot(dirs[i], h.geoNormal) > 0.0f;
                found[i].setOnly(int32_t(h.shapeId),
                                 inside ? s.interiorMediumId : s.exteriorMediumId);
                break;
            }
            r = spawnRay(h, dirs[i]);
        }
    }
    if (found[1].mediumId() == found[2].mediumId() && found[0].mediumId() != found[1].mediumId())
        return found[1];
    return found[0];
}

namespace {

/// Walks from `from` along dir for up to maxDist (kInf: to infinity) through imaginary and
/// skipped boundaries, accumulating the chain; blocked on a real surface. For a finite walk,
/// target = from + maxDist * dir is the end point, and each leg after a crossing aims at it
/// again: the crossing's origin offset moves the ray off the line by ~eps, and keeping the
/// old direction and remaining length would, at grazing angles to a surface at the target
/// (an area light), reach that surface before the target (the end offset is ~eps as well).
MediumShadow walkShadow(const Scene& scene, Vec3 from, Vec3 dir, float maxDist, MediumStack stack) {
    ChainPdfs chain;
    if (scene.everyHitIsReal(stack)) {
        // The walk below would stop at its first hit, blocked: one any-hit query, cheaper
        // than the nearest hit, decides it, and the open segment is one of stack's medium.
        if (scene.anyHitWithin(from, dir, maxDist)) return blockedShadow();
        chain.add(scene, stack.mediumId(), from, dir,
                  maxDist >= kInf ? kMediumFarDistance : maxDist);
        return chain.result();
    }
    const bool finite = maxDist < kInf;
    // One traversal for the whole segment when the scene allows: blocked by a surface real
    // for every stack, or the crossings in order, each decided with the stack of its side.
    // Cheaper than walking hit by hit (a nearest-hit query per leg, each reading the hit's
    // shading data): the shadow walks were a quarter of a bunny bpt iteration, and bpt became
    // 12-15% faster on the bunny and mirrorballs (docs/performance.md, session 29).
    Scene::ShadowCrossing crossings[MediumTrace::kMaxSegments];
    int count = 0;
    switch (
        scene.shadowCrossings(from, dir, maxDist, crossings, MediumTrace::kMaxSegments, &count)) {
        case Scene::ShadowQuery::kBlocked:
            return blockedShadow();
        case Scene::ShadowQuery::kOpen: {
            float t = 0.0f;
            for (int i = 0; i < count; ++i) {
                const Scene::ShadowCrossing& c = crossings[i];
                if (scene.realFor(c.shapeId, stack.priority())) return blockedShadow();
                chain.add(scene, stack.mediumId(), from + dir * t, dir, c.t - t);
                if (!scene.applyCrossing(c.shapeId, c.entering, &stack)) return blockedShadow();
                t = c.t;
            }
            chain.add(scene, stack.mediumId(), from + dir * t, dir,
                      finite ? maxDist - t : kMediumFarDistance);
            return chain.result();
        }
        case Scene::ShadowQuery::kUnavailable:
            break;
    }
    const Vec3 target = finite ? from + dir * maxDist : Vec3(0.0f);
    float remaining = maxDist;
    for (int guard = 0; guard < MediumTrace::kMaxSegments; ++guard) {
        Ray r;
        r.org = from;
        r.dir = dir;
        r.tMin = 0.0f;
        r.tMax = remaining;
        Hit h;
        if (!scene.intersect(r, &h)) {
            float len = remaining >= kInf ? kMediumFarDistance : remaining;
            chain.add(scene, stack.mediumId(), from, dir, len);
            return chain.result();
        }
        if (scene.realFor(h.shapeId, stack.priority())) return blockedShadow();
        chain.add(scene, stack.mediumId(), from, dir, length(h.pos - from));
        if (!scene.crossBoundary(h.shapeId, h.geoNormal, dir, &stack)) return blockedShadow();
        Vec3 next = Scene::offsetRayOrigin(h.pos, h.geoNormal, dir);
        if (finite) {
            const Vec3 toTarget = target - next;
            remaining = dot(toTarget, dir);
            if (!(remaining > 0.0f)) return chain.result();
            remaining = length(toTarget);
            dir = toTarget / remaining;
        }
        from = next;
    }
    return blockedShadow();  // more crossings than a trace can hold: treated as blocked
}

}  // namespace

MediumShadow Scene::shadowTransmittance(const Vec3& a, const Vec3& geoNormalA,
                                        const MediumStack& stackA, const Vec3& b,
                                        const Vec3& geoNormalB) const {
    Vec3 oa = offsetRayOrigin(a, geoNormalA, b - a);
    Vec3 ob = offsetRayOrigin(b, geoNormalB, a - b);
    Vec3 d = ob - oa;
    float len = length(d);
    if (!(len > 0.0f)) return MediumShadow();
    return walkShadow(*this, oa, d / len, len, stackA);
}

MediumShadow Scene::shadowTransmittanceToInfinity(const Vec3& a, const Vec3& geoNormalA,
                                                  const MediumStack& stackA,
                                                  const Vec3& dir) const {
    return walkShadow(*this, offsetRayOrigin(a, geoNormalA, dir), dir, kInf, stackA);
}

}  // namespace ub
