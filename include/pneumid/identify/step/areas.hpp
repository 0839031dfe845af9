// Method of moments / characteristic areas of the step response.
//
// For a stable process G(s) = K (1 + b1 s + ...) / (1 + a1 s + ...) exp(-Td s)
// the Taylor series at s = 0 is G(s) = A0 - A1 s + A2 s^2 - A3 s^3 + ...,
// and the coefficients are areas of the (du-normalized) step response h(t)
// computed by repeated integration (Rake; Vrancic, Strmcnik and Juricic [1],
// used by Pavkovic, Polak and Zorc [2]):
//   A0 = K,   y1(t) = int_0^t (A0 - h) dt,   A1 = y1(inf),
//   y2(t) = int_0^t (A1 - y1) dt,  A2 = y2(inf),  ... (here up to A3).
// A1 / K = T_ar, the average residence time (for an FOPDT, tau + theta).
// FOPDT by the area method of Astrom and Hagglund [3, sec. 2.7]:
//   T_ar = A1 / K,  tau = e * int_0^T_ar r(t) dt,  theta = T_ar - tau
// (r the normalized response). Integrals use the trapezoidal rule over the
// record, and the record end stands in for infinity.
//
// [1] D. Vrancic, S. Strmcnik, D. Juricic, A magnitude optimum multiple
//     integration tuning method for filtered PID controller, Automatica 37
//     (2001) 1473-1479.
// [2] D. Pavkovic, S. Polak, D. Zorc, ISA Transactions 53 (2014) 85-96.
// [3] K. J. Astrom, T. Hagglund, PID Controllers: Theory, Design and Tuning,
//     2nd ed., ISA 1995.
#pragma once

#include "pneumid/identify/step/step_analysis.hpp"

namespace pneumid {

/// Characteristic areas A0..A3 of a step response and the area-method FOPDT.
struct AreaResult {
  /// A0 = K, the static gain (output units per input unit).
  double A0 = 0.0, A1 = 0.0, A2 = 0.0, A3 = 0.0;  ///< characteristic areas (K s^k)
  /// @var A1
  /// First area, K T_ar (gain units times s): the integral of A0 - h(t).
  /// @var A2
  /// Second area (gain units times s^2), the integral of A1 - y1(t).
  double T_ar = 0.0;                              ///< average residence time A1 / A0, s
  FopdtParams fopdt;                              ///< Astrom-Hagglund area-method FOPDT
};

/// Characteristic areas and the area-method FOPDT of an analyzed step.
/// @throws DataError when T_ar <= 0 or lies beyond the record.
AreaResult CharacteristicAreas(const StepAnalysis& step);

}  // namespace pneumid
