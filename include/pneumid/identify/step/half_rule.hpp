// Skogestad's half rule: reduction of a higher-order model to FOPDT or SOPDT
// [1, sec. 2.2]. Write the model as
//   G(s) = K prod_j (-T0j s + 1) / prod_i (tau_i0 s + 1) exp(-theta0 s),
// tau_10 >= tau_20 >= ... Then
//   FOPDT: tau = tau_10 + tau_20 / 2,
//          theta = theta0 + tau_20 / 2 + sum_{i>=3} tau_i0 + sum_j T0j + h / 2
//   SOPDT: tau1 = tau_10, tau2 = tau_20 + tau_30 / 2,
//          theta = theta0 + tau_30 / 2 + sum_{i>=4} tau_i0 + sum_j T0j + h / 2
// (T0j > 0: right-half-plane zeros, counted as delay; h: sample time of a
// digital implementation, 0 by default). A left-half-plane zero (T0 s + 1)
// is cancelled against the denominator time constant tau0 closest to it from
// above by Skogestad's rules [1, Eq. 11]: T0 >= tau0 >= theta gives the gain
// factor T0/tau0; T0 >= theta >= tau0 gives T0/theta; theta >= T0 gives 1
// (the factors then leave the model); tau0 > T0 gives
// (tau~0 / tau0) / ((tau~0 - T0) s + 1) with tau~0 = min(tau0, 5 theta) (the
// lag tau0 is replaced by tau~0 - T0 and the gain scaled). theta here is the
// effective delay without the zero, as Skogestad suggests for a first pass.
// Complex pole or zero pairs s^2/w^2 + 2 zeta s/w + 1 are approximated by one
// first-order factor of time constant 2 zeta / w (matching the first moment,
// i.e. the s coefficient); a complex zero pair with negative s coefficient
// acts as an inverse response (added to the delay). Discrete models are first
// converted with the zero-order-hold d2c.
//
// [1] S. Skogestad, Simple analytic rules for model reduction and PID
//     controller tuning, Journal of Process Control 13 (2003) 291-309.
#pragma once

#include <string>
#include <vector>

#include "pneumid/identify/step/step_analysis.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// FOPDT and SOPDT approximations of a model by Skogestad's half rule.
struct HalfRuleResult {
  FopdtParams fopdt;  ///< K, tau = tau_10 + tau_20 / 2, theta with the half-rule delay (s)
  SopdtParams sopdt;  ///< K, tau1 = tau_10, tau2 = tau_20 + tau_30 / 2, theta (s)
  std::vector<std::string> notes;  ///< approximations applied (complex pairs, zeros)
};

/// Applies the half rule to a stable model with DC gain != 0.
/// @param g  continuous or discrete transfer function
/// @param h  sample time of a digital implementation (s), adds h/2 to the delay
/// @throws InvalidArgument for an unstable or integrating model, zero gain, h < 0,
///         or a discrete model without a real zero-order-hold continuous equivalent.
HalfRuleResult HalfRule(const TransferFunction& g, double h = 0.0);

}  // namespace pneumid
