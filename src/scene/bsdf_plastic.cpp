// Coated-diffuse and thin-sheet BSDFs: Plastic, RoughPlastic, ThinDielectric, as Mitsuba 3
// defines its `plastic`, `roughplastic` and `thindielectric` plugins (conventions: bsdf.h;
// the shared lobe math and its references: kernels/shared/ub_plastic.h).
//
// Plastic (smooth coating of relative IOR eta = `ior` = int_ior / ext_ior):
//   delta reflection   weight specular * F(cos_fix)             (F: exact Fresnel, eta)
//   diffuse            f = base / (pi eta^2) * (1 - F(cos_fix)) (1 - F(cos_gen)),
//                      base = diffuse / (1 - Fdr_int) (or / (1 - diffuse Fdr_int) when
//                      `nonlinear`), Fdr_int = ub_fresnel_diffuse_reflectance(1 / eta).
// RoughPlastic (GGX coating, roughness `alpha`):
//   glossy             f = specular F(fix.h) D(h) G1(fix) G1(gen) / (4 cos_fix cos_gen)
//                      (Walter et al. 2007, eq. 20, with Mitsuba's separable Smith G);
//   diffuse            f = base / (pi eta^2) * T(cos_fix) T(cos_gen), where T is the rough
//                      coating's transmittance and base uses the rough coating's internal
//                      reflectance (prepareMaterial() tabulates both, see below).
// Lobe selection (both plastics, Mitsuba 3): with w = mean(specular) / (mean(diffuse) +
// mean(specular)) and R = F(cos) (smooth) or 1 - T(cos) (rough) seen from a direction,
//   P(specular | dir) = R w / (R w + (1 - R)(1 - w)).
// Unlike Mitsuba, the means are those of the colours at the hit (textures resolved),
// not of the whole texture: only the variance differs. The pdf of the diffuse lobe is
// (1 - P(specular | dirFix)) cos_gen / pi; the reverse pdf uses P(specular | dirGen) and
// cos_fix, so both are exact. Plastics are reflective only; f is symmetric in the two
// directions (no transport-mode dependence besides the shading-normal factor). They are
// two-sided by default like the other opaque materials (Mitsuba's are one-sided unless
// wrapped in `twosided`: loaders set Material::twoSided = false for that).
//
// ThinDielectric: delta reflection with probability and weight R' = 2r / (1 + r), r =
// F(|cos_fix|, ior), tint `specular`; delta transmission along -dirFix with 1 - R', tint
// `transmittance` (kEventRefract). Both sides are alike (normals are not flipped and
// only |cos| matters); the sheet has no inside: the light exits into the medium it came
// from, so the transmitted radiance gets no eta^2 factor. A volume integrator must not
// treat the crossing as entering or leaving a medium: give thin sheets the same medium on
// both sides (Mitsuba's thindielectric is a `null`-like transmission in the same way).
//
// Rough coating tables (prepareMaterial), as Mitsuba 3's roughplastic computes them:
//   T(mu)  = integral over visible normals m of wi of (1 - F(wi.m)) G1(wo, m) for the
//            refracted wo (zero if wo leaves above), mu = wi.z, at mu_k = max(1e-6,
//            k / 63), k = 0..63 (linear interpolation in between);
//   Fint   = 2 * (1/64) sum_k mu_k R_in(mu_k), R_in the analogous reflected energy
//            from inside (relative IOR 1/eta): Mitsuba's discretisation of the
//            hemispherical average 2 int R mu dmu, kept so renders match Mitsuba.
// The visible-normal integrals use a tensor Gauss-Legendre rule on the sampler's unit
// square (32 x 32 nodes when the relative IOR > 1, 128 x 128 otherwise: the total
// internal reflection edge needs more), like Mitsuba.
#include <tbb/parallel_for.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/sampling.h"
#include "kernels/shared/ub_fresnel.h"
#include "kernels/shared/ub_microfacet.h"
#include "kernels/shared/ub_phong.h"
#include "kernels/shared/ub_plastic.h"
#include "scene/bsdf.h"
#include "scene/microfacet_sampling.h"

namespace ub {

namespace {

constexpr float kMinAlphaPlastic = 1e-4f;  // as ggxAlpha() in bsdf.cpp
constexpr double kPiD = 3.14159265358979323846;

float plasticAlpha(const Material& m) {
    return std::max(m.alpha, kMinAlphaPlastic);
}

float mean3(const Rgb& c) {
    return (c.x + c.y + c.z) / 3.0f;
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton iteration on P_n from the
/// Chebyshev guesses cos(pi (i - 1/4) / (n + 1/2)); Abramowitz & Stegun 25.4.29).
void gaussLegendre(int n, std::vector<double>* nodes, std::vector<double>* weights) {
    nodes->assign(size_t(n), 0.0);
    weights->assign(size_t(n), 0.0);
    for (int i = 0; i < (n + 1) / 2; ++i) {
        double x = std::cos(kPiD * (i + 0.75) / (n + 0.5));
        double dp = 0.0;
        for (int iter = 0; iter < 100; ++iter) {
            // P_n(x) by the three-term recurrence, P_n'(x) from P_n and P_{n-1}.
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; ++k) {
                double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            double pn = n == 1 ? x : p1, pm = n == 1 ? 1.0 : p0;
            dp = n * (x * pn - pm) / (x * x - 1.0);
            double dx = pn / dp;
            x -= dx;
            if (std::fabs(dx) < 1e-15) break;
        }
        (*nodes)[size_t(i)] = -x;
        (*nodes)[size_t(n - 1 - i)] = x;
        double w = 2.0 / ((1.0 - x * x) * dp * dp);
        (*weights)[size_t(i)] = w;
        (*weights)[size_t(n - 1 - i)] = w;
    }
}

/// Energy that a rough dielectric interface of relative IOR eta (transmitted side over
/// wi's side) reflects (transmit = false) or transmits (true) for wi = (sin, 0, mu),
/// single scattering: E over visible normals of F or 1 - F, times G1 of the outgoing
/// direction, zero where it leaves on the wrong side.
double roughInterfaceEnergy(float mu, float eta, float alpha, uint32_t dist, bool transmit) {
    std::vector<double> nodes, weights;
    gaussLegendre(eta > 1.0f ? 32 : 128, &nodes, &weights);
    const Vec3 wi(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
    double sum = 0.0;
    for (size_t a = 0; a < nodes.size(); ++a)
        for (size_t b = 0; b < nodes.size(); ++b) {
            const float u1 = float(0.5 * nodes[a] + 0.5), u2 = float(0.5 * nodes[b] + 0.5);
            const Vec3 m = sampleVisibleNormal(dist, wi, alpha, u1, u2);
            const float cosI = dot(wi, m);
            if (!(cosI > 0.0f)) continue;
            float cosT;
            const float fresnel = ub_fresnel_dielectric_ct(cosI, eta, &cosT);
            double value;
            if (transmit) {
                if (fresnel >= 1.0f) continue;
                // Snell with relative IOR eta: t = -wi / eta + (cosI / eta - cosT) m.
                const Vec3 wo = -wi / eta + (cosI / eta - cosT) * m;
                if (!(wo.z < 0.0f)) continue;
                value = (1.0 - fresnel) * ub_mf_g1(dist, -wo.z, alpha);
            } else {
                const Vec3 wo = 2.0f * cosI * m - wi;
                if (!(wo.z > 0.0f)) continue;
                value = fresnel * ub_mf_g1(dist, wo.z, alpha);
            }
            sum += value * weights[a] * weights[b] * 0.25;
        }
    return sum;
}

}  // namespace

void prepareMaterial(Material& m) {
    switch (m.type) {
        case MaterialType::Plastic:
            m.internalReflectance = ub_fresnel_diffuse_reflectance(1.0f / m.ior);
            break;
        case MaterialType::RoughPlastic: {
            const float alpha = plasticAlpha(m);
            const uint32_t dist = uint32_t(m.distribution);
            const int n = UB_ROUGH_PLASTIC_TABLE_SIZE;
            // The 64 table entries in parallel (each independent), summed in order.
            std::vector<double> internalAt(size_t(n), 0.0);
            tbb::parallel_for(0, n, [&](int k) {
                const float mu = std::max(1e-6f, float(k) / float(n - 1));
                m.coatingTransmittance[size_t(k)] =
                    float(roughInterfaceEnergy(mu, m.ior, alpha, dist, true));
                internalAt[size_t(k)] =
                    roughInterfaceEnergy(mu, 1.0f / m.ior, alpha, dist, false) * mu;
            });
            double internal = 0.0;
            for (double v : internalAt) internal += v;
            m.internalReflectance = float(2.0 * internal / n);
            break;
        }
        default:
            break;
    }
    m.preparedIor = m.ior;
    m.preparedAlpha = m.alpha;
    m.preparedDistribution = m.distribution;
}

// ---- Bsdf members ------------------------------------------------------------------

void Bsdf::setupPlastic() {
    const Material& mat = *mat_;
    if (mat.type == MaterialType::ThinDielectric) {
        fresnelFix_ = ub_thin_dielectric_reflectance(
            ub_fresnel_dielectric(std::fabs(localDirFix_.z), mat.ior));
        contProb_ = maxComponent(colors_.specular * fresnelFix_ +
                                 colors_.transmittance * (1.0f - fresnelFix_));
        return;
    }
    if (mat.preparedIor != mat.ior || mat.preparedAlpha != mat.alpha ||
        mat.preparedDistribution != mat.distribution)
        throw std::logic_error("Bsdf::setup: plastic material '" + mat.name +
                               "' was not prepared (call prepareMaterial after setting ior/alpha)");
    const float meanDiffuse = mean3(colors_.diffuse), meanSpecular = mean3(colors_.specular);
    if (!(meanDiffuse + meanSpecular > 0.0f)) {
        black_ = true;
        return;
    }
    specularWeight_ = meanSpecular / (meanDiffuse + meanSpecular);
    for (int c = 0; c < 3; ++c)
        plasticBase_[c] =
            ub_plastic_base(colors_.diffuse[c], mat.internalReflectance, mat.nonlinear ? 1 : 0);
    if (black_) return;  // back of a one-sided plastic
    const float cosFix = localDirFix_.z;
    // Albedo estimate for Russian roulette: the coating's reflectance plus what enters.
    float reflectance;
    if (mat.type == MaterialType::Plastic) {
        fresnelFix_ = ub_fresnel_dielectric(cosFix, mat.ior);
        reflectance = fresnelFix_;
    } else {
        reflectance = 1.0f - plasticTransmittance(cosFix);
    }
    contProb_ =
        maxComponent(colors_.specular * reflectance + colors_.diffuse * (1.0f - reflectance));
}

float Bsdf::plasticTransmittance(float cosTheta) const {
    return ub_plastic_table_lookup(mat_->coatingTransmittance.data(), cosTheta);
}

float Bsdf::plasticSpecularProb(float cosTheta) const {
    return ub_bsdf_plastic_specular_prob(&shared_, coating_, cosTheta);
}

}  // namespace ub
