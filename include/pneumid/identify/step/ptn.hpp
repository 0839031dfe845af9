// Equivalent PTn model by the tangent-line method (paper [1, Eq. 3], after
// Pavkovic, Polak and Zorc [2]). The FOPDT of the tangent construction,
// kp exp(-td s) / (1 + tTL s), is written as kp / ((1 + tTL s) exp(td s)) and
// the denominator is replaced by its Taylor expansion truncated after s^n:
//   G_PTn(s) = kp / (1 + a1 s + a2 s^2 + ... + an s^n),
//   a_i = td^i / i! + tTL td^(i-1) / (i-1)!,
// so a1 = td + tTL, a2 = (td/2 + tTL) td, a3 = (td/6 + tTL/2) td^2.
// The paper prints the s^3 term as (td/6 + tTL/2) td, which lacks a factor td
// (it would not have units of s^3); the expansion above is implemented.
// Paper, n = 2: kp = 1.6, a1 = 0.2387, a2 = 2.39e-4 (td ~ 0.001 s, tTL ~ 0.2377 s).
// For n >= 5 the truncated series can have right-half-plane roots; callers
// check IsStable().
//
// [1] A. A. M. Emhemed, R. Mamat, A. A. M. Faudzi, Jurnal Teknologi 77:20
//     (2015) 115-119, Eq. 3.
// [2] D. Pavkovic, S. Polak, D. Zorc, ISA Transactions 53 (2014) 85-96.
#pragma once

#include <vector>

#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Denominator coefficients a_0 = 1, a_1, ..., a_n in ascending powers of s.
/// @param td   delay time from the tangent construction, s (>= 0)
/// @param tTL  time constant from the tangent construction, s (> 0)
/// @param n    order (1 <= n <= 20)
/// @throws InvalidArgument for td < 0, tTL <= 0 or n out of range.
std::vector<double> PtnCoefficients(double td, double tTL, int n);

/// kp / (1 + a1 s + ... + an s^n), continuous, no delay.
/// @throws InvalidArgument as PtnCoefficients, or for a non-finite kp.
TransferFunction PtnModel(double kp, double td, double tTL, int n);

}  // namespace pneumid
