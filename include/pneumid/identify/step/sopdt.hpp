// SOPDT K exp(-theta s) / ((tau1 s + 1)(tau2 s + 1)) from three points of the
// step response (a three-point method in the spirit of Rangaiah and
// Krishnaswamy [1]; points and solution as follows).
//
// With q = tau2 / tau1 in [0, 1] and x = (t - theta) / tau1, the normalized
// response is
//   h_q(x) = 1 - (exp(-x) - q exp(-x / q)) / (1 - q)     (q < 1)
//   h_1(x) = 1 - (1 + x) exp(-x)                         (equal lags)
//   h_0(x) = 1 - exp(-x)                                 (first order).
// Let t20, t50, t80 be the times at which the response reaches 20, 50 and
// 80 %, and x_p(q) the solution of h_q(x) = p. The ratio
//   R = (t80 - t50) / (t50 - t20) = (x80 - x50) / (x50 - x20)
// does not depend on theta or tau1 and falls monotonically from 1.949 (q = 0)
// to 1.541 (q = 1); q is found from R by bisection, then
//   tau1 = (t80 - t20) / (x80(q) - x20(q)),  tau2 = q tau1,
//   theta = t50 - tau1 x50(q).
// R above 1.949 (a response faster than first order at the start) gives q = 0;
// R below 1.541 (more than two lags) gives q = 1: both are reported in
// `clamped`. theta is clipped at 0.
//
// [1] G. P. Rangaiah, P. R. Krishnaswamy, Estimating second-order plus dead
//     time model parameters, Ind. Eng. Chem. Res. 33 (1994) 1867-1871.
#pragma once

#include "pneumid/identify/step/step_analysis.hpp"

namespace pneumid {

/// SOPDT of the three-point method with the measured ratio R.
struct ThreePointSopdtResult {
  SopdtParams params;  ///< K, tau1 >= tau2 (s), theta >= 0 (s)
  double ratio = 0.0;    ///< R measured
  bool clamped = false;  ///< R outside [1.541, 1.949], q set to the nearest end
};

/// Normalized SOPDT step response h_q(x) (see above), q in [0, 1], x >= 0.
double SopdtNormalizedStep(double q, double x);
/// Solution x of h_q(x) = p for p in (0, 1).
double SopdtNormalizedTime(double q, double p);

/// SOPDT by the three-point method.
/// @throws DataError when a level is never reached or the times are not increasing.
ThreePointSopdtResult ThreePointSopdt(const StepAnalysis& step);

}  // namespace pneumid
