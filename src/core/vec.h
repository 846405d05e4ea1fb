// Small fixed-size vector math used by all host code.
// Vec3 holds points, directions and RGB values (alias Rgb). Host-only: the
// OpenCL-shared scalar math lives in kernels/shared/.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace ub {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 1.0f / kPi;
constexpr float kInf = 1e30f;

struct Vec2 {
    float x = 0, y = 0;
    Vec2() = default;
    Vec2(float x_, float y_) : x(x_), y(y_) {}
};

struct Vec3 {
    float x = 0, y = 0, z = 0;
    Vec3() = default;
    explicit Vec3(float v) : x(v), y(v), z(v) {}
    Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}

    float operator[](int i) const { return (&x)[i]; }
    float& operator[](int i) { return (&x)[i]; }
    Vec3 operator-() const { return {-x, -y, -z}; }
    Vec3& operator+=(const Vec3& b) {
        x += b.x;
        y += b.y;
        z += b.z;
        return *this;
    }
    Vec3& operator-=(const Vec3& b) {
        x -= b.x;
        y -= b.y;
        z -= b.z;
        return *this;
    }
    Vec3& operator*=(const Vec3& b) {
        x *= b.x;
        y *= b.y;
        z *= b.z;
        return *this;
    }
    Vec3& operator*=(float s) {
        x *= s;
        y *= s;
        z *= s;
        return *this;
    }
    Vec3& operator/=(float s) {
        float inv = 1.0f / s;
        x *= inv;
        y *= inv;
        z *= inv;
        return *this;
    }
};

using Rgb = Vec3;

inline Vec3 operator+(Vec3 a, const Vec3& b) {
    return a += b;
}
inline Vec3 operator-(Vec3 a, const Vec3& b) {
    return a -= b;
}
inline Vec3 operator*(Vec3 a, const Vec3& b) {
    return a *= b;
}
inline Vec3 operator/(const Vec3& a, const Vec3& b) {
    return {a.x / b.x, a.y / b.y, a.z / b.z};
}
inline Vec3 operator*(Vec3 a, float s) {
    return a *= s;
}
inline Vec3 operator*(float s, Vec3 a) {
    return a *= s;
}
inline Vec3 operator/(Vec3 a, float s) {
    return a /= s;
}

inline float dot(const Vec3& a, const Vec3& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float lengthSqr(const Vec3& a) {
    return dot(a, a);
}
inline float length(const Vec3& a) {
    return std::sqrt(dot(a, a));
}
inline Vec3 normalize(const Vec3& a) {
    return a / length(a);
}
inline Vec3 vmin(const Vec3& a, const Vec3& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
inline Vec3 vmax(const Vec3& a, const Vec3& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
inline float maxComponent(const Vec3& a) {
    return std::max(a.x, std::max(a.y, a.z));
}
inline float minComponent(const Vec3& a) {
    return std::min(a.x, std::min(a.y, a.z));
}
inline float average(const Vec3& a) {
    return (a.x + a.y + a.z) * (1.0f / 3.0f);
}
/// Rec. 709 luminance of a linear RGB value.
inline float luminance(const Rgb& c) {
    return 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z;
}
inline bool isBlack(const Rgb& c) {
    return c.x == 0 && c.y == 0 && c.z == 0;
}
inline bool isFinite(const Vec3& a) {
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
inline Vec3 reflect(const Vec3& dir, const Vec3& n) {
    return 2.0f * dot(dir, n) * n - dir;
}

/// Axis-aligned bounding box.
struct Bounds3 {
    Vec3 lo{kInf, kInf, kInf};
    Vec3 hi{-kInf, -kInf, -kInf};
    void extend(const Vec3& p) {
        lo = vmin(lo, p);
        hi = vmax(hi, p);
    }
    void extend(const Bounds3& b) {
        lo = vmin(lo, b.lo);
        hi = vmax(hi, b.hi);
    }
    bool empty() const { return lo.x > hi.x; }
    Vec3 center() const { return 0.5f * (lo + hi); }
};

/// Orthonormal frame; z is the normal. toLocal/toWorld convert directions.
struct Frame {
    Vec3 s{1, 0, 0}, t{0, 1, 0}, n{0, 0, 1};
    Frame() = default;
    /// Builds a frame around unit normal n (Duff et al. 2017, branchless ONB).
    explicit Frame(const Vec3& nn) : n(nn) {
        float sign = std::copysign(1.0f, n.z);
        float a = -1.0f / (sign + n.z);
        float b = n.x * n.y * a;
        s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
        t = Vec3(b, sign + n.y * n.y * a, -n.y);
    }
    Vec3 toLocal(const Vec3& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
    Vec3 toWorld(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

/// Row-major 4x4 affine transform (points and directions; normals via inverse transpose).
struct Transform {
    float m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    static Transform translate(const Vec3& t);
    static Transform scale(const Vec3& s);
    /// Rotation by angleDeg degrees about axis (right-handed).
    static Transform rotate(float angleDeg, const Vec3& axis);
    /// Camera-style look-at: maps local +z to (target - origin).
    static Transform lookAt(const Vec3& origin, const Vec3& target, const Vec3& up);
    Transform operator*(const Transform& b) const;
    Vec3 point(const Vec3& p) const;
    Vec3 vector(const Vec3& v) const;
    /// Transforms a normal with the inverse transpose (returns unnormalized).
    Vec3 normal(const Vec3& nrm) const;
    Transform inverse() const;
    float determinant3() const;
};

}  // namespace ub
