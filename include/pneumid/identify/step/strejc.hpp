// Strejc's method: n equal lags with an extra dead time [1], [2, sec. 3.3],
//   G(s) = K exp(-Td s) / (T s + 1)^n,
// from the tangent at the inflection point (delay time Tu, time constant Tn,
// see tangent.hpp). For (T s + 1)^-n the normalized step response is
// h(x) = 1 - exp(-x) sum_{k<n} x^k / k!, x = t / T, with its inflection at
// x_i = n - 1 and slope h'(x_i) = x_i^(n-1) exp(-x_i) / (n-1)!, so
//   Tn / T = 1 / h'(x_i),   Tu / T = x_i - h(x_i) / h'(x_i)
// (n = 2: Tu/Tn = 0.104, n = 3: 0.218, n = 4: 0.319, n = 5: 0.410, the
// classical table, computed here exactly). The order is the largest n whose
// Tu/Tn does not exceed the measured ratio; then T = Tn / (Tn/T)_n and the
// remaining delay Td = Tu - (Tu/T)_n T >= 0.
//
// [1] V. Strejc, Naherungsverfahren fur aperiodische Ubergangscharakteristiken,
//     Regelungstechnik 7 (1959) 124-128.
// [2] H. Unbehauen, Regelungstechnik I, Vieweg+Teubner, 15th ed. 2008, sec. 3.3.
#pragma once

#include "pneumid/identify/step/step_analysis.hpp"
#include "pneumid/identify/step/tangent.hpp"

namespace pneumid {

/// Strejc's model K exp(-Td s) / (T s + 1)^n from the inflection tangent's Tu and Tn.
struct StrejcResult {
  int n = 1;           ///< number of equal lags
  double K = 0.0;      ///< gain
  double T = 0.0;      ///< lag time constant, s
  double Td = 0.0;     ///< extra dead time, s
  double ratio = 0.0;  ///< measured Tu / Tn
};

/// Table entries (Tu/T, Tn/T) of n equal lags, n >= 1.
/// @throws InvalidArgument for n < 1.
std::pair<double, double> StrejcTable(int n);

/// Strejc model from a tangent construction and gain K, orders 1..max_order.
/// @throws InvalidArgument when tangent.T <= 0 or max_order < 1.
StrejcResult Strejc(const TangentResult& tangent, double K, int max_order = 10);

}  // namespace pneumid
