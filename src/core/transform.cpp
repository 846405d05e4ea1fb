#include "core/vec.h"

namespace ub {

Transform Transform::translate(const Vec3& t) {
    Transform r;
    r.m[0][3] = t.x;
    r.m[1][3] = t.y;
    r.m[2][3] = t.z;
    return r;
}

Transform Transform::scale(const Vec3& s) {
    Transform r;
    r.m[0][0] = s.x;
    r.m[1][1] = s.y;
    r.m[2][2] = s.z;
    return r;
}

Transform Transform::rotate(float angleDeg, const Vec3& axisIn) {
    Vec3 a = normalize(axisIn);
    float th = angleDeg * kPi / 180.0f;
    float c = std::cos(th), s = std::sin(th), oc = 1.0f - c;
    Transform r;
    r.m[0][0] = c + a.x * a.x * oc;
    r.m[0][1] = a.x * a.y * oc - a.z * s;
    r.m[0][2] = a.x * a.z * oc + a.y * s;
    r.m[1][0] = a.y * a.x * oc + a.z * s;
    r.m[1][1] = c + a.y * a.y * oc;
    r.m[1][2] = a.y * a.z * oc - a.x * s;
    r.m[2][0] = a.z * a.x * oc - a.y * s;
    r.m[2][1] = a.z * a.y * oc + a.x * s;
    r.m[2][2] = c + a.z * a.z * oc;
    return r;
}

Transform Transform::lookAt(const Vec3& origin, const Vec3& target, const Vec3& up) {
    Vec3 dir = normalize(target - origin);
    Vec3 left = normalize(cross(up, dir));
    Vec3 newUp = cross(dir, left);
    Transform r;
    for (int i = 0; i < 3; ++i) {
        r.m[i][0] = left[i];
        r.m[i][1] = newUp[i];
        r.m[i][2] = dir[i];
        r.m[i][3] = origin[i];
    }
    return r;
}

Transform Transform::operator*(const Transform& b) const {
    Transform r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            float s = 0;
            for (int k = 0; k < 4; ++k) s += m[i][k] * b.m[k][j];
            r.m[i][j] = s;
        }
    return r;
}

Vec3 Transform::point(const Vec3& p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
}

Vec3 Transform::vector(const Vec3& v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

Vec3 Transform::normal(const Vec3& nrm) const {
    Transform inv = inverse();
    // Inverse transpose applied to a covector.
    return {inv.m[0][0] * nrm.x + inv.m[1][0] * nrm.y + inv.m[2][0] * nrm.z,
            inv.m[0][1] * nrm.x + inv.m[1][1] * nrm.y + inv.m[2][1] * nrm.z,
            inv.m[0][2] * nrm.x + inv.m[1][2] * nrm.y + inv.m[2][2] * nrm.z};
}

float Transform::determinant3() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

Transform Transform::inverse() const {
    // General 4x4 inverse by Gauss-Jordan elimination with partial pivoting
    // (double precision to keep round trips exact to float precision).
    double a[4][8];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            a[i][j] = m[i][j];
            a[i][j + 4] = (i == j) ? 1.0 : 0.0;
        }
    for (int c = 0; c < 4; ++c) {
        int piv = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::fabs(a[r][c]) > std::fabs(a[piv][c])) piv = r;
        if (a[piv][c] == 0.0) return Transform();  // singular: callers validate determinant3()
        if (piv != c)
            for (int j = 0; j < 8; ++j) std::swap(a[c][j], a[piv][j]);
        double inv = 1.0 / a[c][c];
        for (int j = 0; j < 8; ++j) a[c][j] *= inv;
        for (int r = 0; r < 4; ++r)
            if (r != c) {
                double f = a[r][c];
                for (int j = 0; j < 8; ++j) a[r][j] -= f * a[c][j];
            }
    }
    Transform r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = float(a[i][j + 4]);
    return r;
}

}  // namespace ub
