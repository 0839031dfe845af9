// FOPDT from the times t1, t2 (after the step) at which the response reaches
// two fractions p1 < p2 of its change [1, Table 7.1]:
//   method                      p1 / p2        tau              theta
//   Smith (1972) [2]            28.3 / 63.2 %  1.5 (t2 - t1)    t2 - tau
//   Sundaresan-Krishnaswamy [3] 35.3 / 85.3 %  0.67 (t2 - t1)   1.3 t1 - 0.29 t2
//   Broida [4]                  28 / 40 %      5.5 (t2 - t1)    2.8 t1 - 1.8 t2
// K = dy/du in every case. theta is clipped at 0 (a note says so).
//
// [1] D. E. Seborg, T. F. Edgar, D. A. Mellichamp, Process Dynamics and
//     Control, 2nd ed., Wiley 2004, sec. 7.2.
// [2] C. L. Smith, Digital Computer Process Control, Intext 1972.
// [3] K. R. Sundaresan, P. R. Krishnaswamy, Estimation of time delay, time
//     constant parameters in time, frequency and Laplace domains, Can. J. Chem.
//     Eng. 56 (1978) 257-262.
// [4] V. Broida, Extrapolation des reponses indicielles aperiodiques, Automatisme
//     XIV (1969) 155-164.
#pragma once

#include <string>

#include "pneumid/identify/step/step_analysis.hpp"

namespace pneumid {

/// Two-point FOPDT method: its response fractions and formulas are in the table above.
enum class TwoPointMethod { kSmith, kSundaresanKrishnaswamy, kBroida };

/// "smith", "sundaresan", "broida" (the `pneumid identify` method names).
std::string ToString(TwoPointMethod method);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
TwoPointMethod TwoPointMethodFromString(const std::string& name);

/// The two response fractions (p1, p2) of a method.
std::pair<double, double> TwoPointLevels(TwoPointMethod method);

/// FOPDT parameters by a two-point method.
/// @throws DataError when a level is never reached or tau comes out <= 0.
FopdtParams TwoPoint(const StepAnalysis& step, TwoPointMethod method);

}  // namespace pneumid
