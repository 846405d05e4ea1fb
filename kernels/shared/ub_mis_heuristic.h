/* Multiple importance sampling heuristics (Veach 1997, Sec. 9.2).
 *
 * ub_mis_power(pdf, exponent) is the per-strategy term: pdf^beta with beta = 2
 * for the power heuristic (Veach eq. 9.13) and beta = 1 for the balance
 * heuristic (eq. 9.10). The weight of strategy a against strategy b, both pdfs
 * in the same measure, is ub_mis_weight2(pdfA, pdfB, beta) =
 * pdfA^beta / (pdfA^beta + pdfB^beta). Shared by host integrators and kernels.
 */
#ifndef UB_MIS_HEURISTIC_H
#define UB_MIS_HEURISTIC_H

#include "ub_defs.h"

UB_INLINE float ub_mis_power(float pdf, float beta) {
    return beta == 2.0f ? pdf * pdf : (beta == 1.0f ? pdf : ub_pow(pdf, beta));
}

/* Weight of the strategy with pdf pdfA when combined with one of pdf pdfB.
 * Returns 1 when pdfB == 0 (b cannot generate the sample) and 0 if both are 0. */
UB_INLINE float ub_mis_weight2(float pdfA, float pdfB, float beta) {
    float a = ub_mis_power(pdfA, beta);
    float b = ub_mis_power(pdfB, beta);
    return (a + b) > 0.0f ? a / (a + b) : 0.0f;
}

#endif /* UB_MIS_HEURISTIC_H */
