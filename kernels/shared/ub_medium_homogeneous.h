/* A homogeneous medium along a beam, in closed form: the ub_segment_eval of
 * [0, t] (transmittance, sigma_s at the end, free-flight densities of stopping at
 * either end and of passing, spectral MIS over RGB: pdfs are channel averages; Novak
 * et al. 2018, Sec. 5.1). The host twins (src/estimators/beam_medium.cpp) and the
 * kernels evaluate homogeneous media with this function. */
#ifndef UB_MEDIUM_HOMOGENEOUS_H
#define UB_MEDIUM_HOMOGENEOUS_H

#include "ub_upbp_records.h"

/* What the kernels know of a medium. 32 bytes. */
typedef struct {
    float sigmaT[3];
    float sigmaS[3];
    float g;
    ub_uint homogeneous; /* 0: a grid (the kernels leave such media to the host) */
} ub_medium_info;

/* exp(-tau) per channel. Grey optical depths (grey media, grids with a grey albedo) take one
 * exponential: the same argument gives the same value, so the result is that of three calls,
 * bit for bit. The tracing passes' transmittances (src/scene/medium*.cpp) use it too. */
UB_INLINE void ub_exp_neg3(float tau0, float tau1, float tau2, float* out) {
    out[0] = ub_exp(-tau0);
    const int grey = tau1 == tau0 && tau2 == tau0;
    out[1] = grey ? out[0] : ub_exp(-tau1);
    out[2] = grey ? out[0] : ub_exp(-tau2);
}

/* The ub_segment_eval of a homogeneous medium from the transmittances T of [0, t]. */
UB_INLINE ub_segment_eval ub_homogeneous_segment_of(ub_medium_info m, UB_PRIVATE const float* T,
                                                    float contProb) {
    ub_segment_eval e;
    float stop = 0.0f, pass = 0.0f;
    UB_UNROLL
    for (int a = 0; a < 3; ++a) {
        e.transmittance[a] = T[a];
        e.sigmaS[a] = m.sigmaS[a];
        stop += m.sigmaT[a] * T[a];
        pass += T[a];
    }
    e.stopFwdL = stop * (1.0f / 3.0f);
    e.stopRevStartL = e.stopFwdL; /* the same extinction at both ends */
    e.passProb = pass * (1.0f / 3.0f);
    e.contProb = contProb;
    return e;
}

/* The medium over [0, t] of a homogeneous medium, its continuation probability given
 * (ub_homogeneous_cont_prob, constant per medium: loops over pairs compute it once). */
UB_INLINE ub_segment_eval ub_homogeneous_segment_cp(ub_medium_info m, float t, float contProb) {
    float T[3];
    ub_exp_neg3(m.sigmaT[0] * t, m.sigmaT[1] * t, m.sigmaT[2] * t, T);
    return ub_homogeneous_segment_of(m, T, contProb);
}

/* The transmittances of n distances in one homogeneous medium, T[3 j + a] = exp(-sigma_t[a] t[j])
 * (a = 0, 1, 2): those of ub_homogeneous_segment_cp at t[j], the same bits, in one loop over the
 * 3 n exponentials, which a vectorising compiler evaluates several at a time (PoCL's, eight
 * wide: ymm registers in the kernel's disassembly). The bb1d and pb2d kernels compute a flush's
 * pairs so (ub_exp_poly's arithmetic on PoCL): the bb1d kernel took 0.80 (bunny) and 0.87
 * (mirrorballs) of its time, pb2d 0.94 (bunny) and 0.98 (mirrorballs, the candle), against
 * ub_homogeneous_segment_cp pair by pair (docs/performance.md, session 48). The host twins keep
 * that: this loop there, eight ub_exp_poly at a time with AVX, was no faster than glibc's expf
 * per pair. */
UB_INLINE void ub_homogeneous_transmittances(ub_medium_info m, UB_PRIVATE const float* t, int n,
                                             UB_PRIVATE float* T) {
    for (int j = 0; j < n; ++j) {
        UB_UNROLL
        for (int a = 0; a < 3; ++a) T[3 * j + a] = -(m.sigmaT[a] * t[j]);
    }
    for (int k = 0; k < 3 * n; ++k) T[k] = ub_exp(T[k]);
}

UB_INLINE float ub_homogeneous_cont_prob(ub_medium_info m) {
    return ub_medium_cont_prob(m.sigmaS[0], m.sigmaS[1], m.sigmaS[2], m.sigmaT[0], m.sigmaT[1],
                               m.sigmaT[2]);
}

#endif /* UB_MEDIUM_HOMOGENEOUS_H */
