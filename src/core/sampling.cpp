#include "core/sampling.h"

#include <algorithm>

namespace ub {

Distribution1D::Distribution1D(const std::vector<float>& f) : func_(f), cdf_(f.size() + 1) {
    int n = int(f.size());
    cdf_[0] = 0;
    for (int i = 0; i < n; ++i) cdf_[i + 1] = cdf_[i] + std::max(0.0f, func_[i]) / float(n);
    funcInt_ = cdf_[n];
    if (funcInt_ == 0) {
        for (int i = 1; i <= n; ++i) cdf_[i] = float(i) / float(n);
    } else {
        for (int i = 1; i <= n; ++i) cdf_[i] /= funcInt_;
    }
}

int Distribution1D::sampleDiscrete(float u, float* pmfOut) const {
    int n = count();
    auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
    int i = std::clamp(int(it - cdf_.begin()) - 1, 0, n - 1);
    // Skip zero-width bins that upper_bound may land on at bin boundaries.
    while (i < n - 1 && cdf_[i + 1] <= u) ++i;
    if (pmfOut) *pmfOut = cdf_[i + 1] - cdf_[i];
    return i;
}

float Distribution1D::sampleContinuous(float u, float* pdfOut, int* binOut) const {
    float pmfV;
    int i = sampleDiscrete(u, &pmfV);
    float du = u - cdf_[i];
    if (pmfV > 0) du /= pmfV;
    if (pdfOut) *pdfOut = pmfV * float(count());
    if (binOut) *binOut = i;
    return std::min((float(i) + du) / float(count()), 0.99999994f);
}

float Distribution1D::pdf(float x) const {
    int i = std::clamp(int(x * count()), 0, count() - 1);
    return (cdf_[i + 1] - cdf_[i]) * float(count());
}

Distribution2D::Distribution2D(const std::vector<float>& f, int nu, int nv) {
    std::vector<float> marg(nv);
    conditional_.reserve(nv);
    for (int v = 0; v < nv; ++v) {
        std::vector<float> row(f.begin() + size_t(v) * nu, f.begin() + size_t(v + 1) * nu);
        conditional_.emplace_back(row);
        marg[v] = conditional_.back().integral();
    }
    marginal_ = Distribution1D(marg);
}

Vec2 Distribution2D::sampleContinuous(const Vec2& u, float* pdfOut) const {
    float pdf0, pdf1;
    int v;
    float y = marginal_.sampleContinuous(u.y, &pdf0, &v);
    float x = conditional_[v].sampleContinuous(u.x, &pdf1);
    if (pdfOut) *pdfOut = pdf0 * pdf1;
    return {x, y};
}

float Distribution2D::pdf(const Vec2& p) const {
    int nv = int(conditional_.size());
    int v = std::clamp(int(p.y * nv), 0, nv - 1);
    return marginal_.pdf(p.y) * conditional_[v].pdf(p.x);
}

}  // namespace ub
