// Uncertainty of identified models' responses: the parameter covariance P an
// estimator computes (IdentifiedModel::covariance) propagated to the step
// response and the Bode diagram, for confidence bands such as MATLAB's
// showConfidence.
//
// Gauss approximation (first-order propagation, [1] sec. 9.6, eq. 9.55): for a
// response r(theta) at a time or frequency,
//
//   Var r ~ J P J^T,   J = dr/dtheta at the estimate,
//
// with J by central finite differences, theta_i +- h_i,
// h_i = relative_step * max(|theta_i|, sqrt(P_ii)): the model is rebuilt from
// the perturbed parameters (PolynomialModel for ARX/ARMAX/OE/BJ/IV4, the
// process transfer function for fit-* models) in the form the response is
// drawn in (the continuous zoh d2c "tf", tustin when zoh has no equivalent,
// or the "discrete" form). A band of K standard deviations is r +- K sd.
// Magnitudes are in dB, phases in degrees; the phase difference is taken as
// arg(G+ / G-) so it does not depend on unwrapping.
//
// Which models have a covariance: polynomial models the full covariance of
// their estimator (PolynomialModel::covariance); fit-* process models the
// full covariance of the fit (ProcessFitResult::covariance; the diagonal
// param_std^2 by SetDiagonalCovariance only when it is not finite); the
// graphical, subspace and correlation
// methods none. A model without a covariance has no band: the functions below
// then return an empty vector (HasCovariance says so beforehand); they never
// throw for it.
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999,
//     sec. 9.6 (variance of the frequency function), eq. 9.55.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

#include "pneumid/identify/identified_model.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// How parameter covariance is propagated to response uncertainty (finite differences).
struct UncertaintyOptions {
  /// Relative finite-difference step h_i / max(|theta_i|, sd_i), in (0, 0.1] (default 1e-5).
  double relative_step = 1e-5;
  /// Propagate through the discrete form (IdentifiedModel::discrete) instead of
  /// "tf" when the model has one (what `pneumid report` plots).
  bool discrete = false;
  /// True when relative_step is in (0, 0.1]; otherwise false with the reason in *error
  /// (when error is not null).
  bool IsValid(std::string* error) const;
};

/// True when `model` has a usable covariance (square, matching names, finite,
/// every name a parameter the model can be rebuilt from).
bool HasCovariance(const IdentifiedModel& model);

/// The parameter values in the order of model.covariance->names.
/// @throws InvalidArgument when the model has no covariance or a name is not a parameter.
Eigen::VectorXd CovarianceParameters(const IdentifiedModel& model);

/// The model's transfer function rebuilt with the covariance parameters set to
/// `theta` (order of covariance->names), in the form of `options.discrete`.
/// @throws InvalidArgument when the model has no covariance, theta has the
///         wrong size or the structure cannot be rebuilt.
TransferFunction ModelWithParameters(const IdentifiedModel& model, const Eigen::VectorXd& theta,
                                     const UncertaintyOptions& options = {});

/// The unit step response of the model's form at times t (s, >= 0): a
/// discrete model held between samples, a continuous one exact on a uniform
/// grid starting at 0 and linearly interpolated otherwise.
/// @throws InvalidArgument for negative or non-finite times.
Eigen::VectorXd StepResponseAt(const TransferFunction& g, const Eigen::VectorXd& t);

/// Standard deviation of the unit step response at times t; empty when the
/// model has no covariance. @throws InvalidArgument for invalid options or times.
Eigen::VectorXd StepResponseStd(const IdentifiedModel& model, const Eigen::VectorXd& t,
                                const UncertaintyOptions& options = {});

/// Standard deviations of the Bode magnitude (dB) and phase (deg).
struct BodeStd {
  Eigen::VectorXd magnitude_db;  ///< standard deviation of 20 log10 |G(jw)|, dB, one per w
  Eigen::VectorXd phase_deg;     ///< standard deviation of arg G(jw), degrees, one per w
};

/// Standard deviations at frequencies w (rad/s, > 0; below pi/Ts for a
/// discrete form); both vectors empty when the model has no covariance.
/// @throws InvalidArgument for invalid options or frequencies.
BodeStd BodeResponseStd(const IdentifiedModel& model, const Eigen::VectorXd& w,
                        const UncertaintyOptions& options = {});

/// Fills model->covariance with the diagonal param_std^2 of the parameters
/// that have a finite standard deviation (fit-* models without a finite full
/// covariance), in the
/// order of `names`; leaves it unset when none has.
void SetDiagonalCovariance(IdentifiedModel* model, const std::vector<std::string>& names);

}  // namespace pneumid
