// A polynomial NARX model (Billings [1] eq. 2.58): its terms, coefficients,
// normalisation, one-step prediction, free-run simulation and JSON form. The
// estimator (term selection by FROLS) is identify/narx.hpp.
//
// Model:
//   y(t) = sum_i theta_i p_i(t) + e(t),
// each term p_i a product of at most `degree` regressors from
//   y(t-1) .. y(t-ny),  u(t-nk) .. u(t-nk-nu+1),
// or the constant 1. The signals enter normalised: the input as
// (u - u_offset) / u_scale, the output as y / y_scale; terms and theta refer
// to the normalised signals, and the model multiplies its output by y_scale.
//
// Simulation (free run): yhat(t) from the model with yhat in place of y; the
// first FirstSample() outputs are taken from the measured output (the model's
// past before it can predict). yhat is held within [y_min, y_max], the
// output band the model was estimated for: a polynomial fitted on a range
// of outputs runs away outside it (the cascaded tanks' free run below the
// estimation record's lowest level went to -1e30 within 40 samples), where
// the band keeps the run at its edge; the estimator sets it to the
// estimation output's range widened by a quarter of it each way (the band of
// the simulation-focus fit, narx_simulation_fit.hpp). Infinite: no band.
//
// JSON form: {"ny": 2, "nu": 2, "nk": 1, "degree": 2, "Ts": 0.01,
//   "terms": ["1", "y(t-1)", "y(t-2)^2", "u(t-1)*y(t-1)"], "theta": [...], "err": [...],
//   "u_offset": 50, "u_scale": 50, "y_scale": 193, "y_min": -48, "y_max": 241}
//   (the last five optional: 0, 1, 1, no band; files before the band load
//   without it).
//
// [1] S. A. Billings, Nonlinear System Identification: NARMAX Methods in the
//     Time, Frequency, and Spatio-Temporal Domains, Wiley, 2013.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace pneumid {

/// One monomial: regressor indices in non-decreasing order, r < ny for
/// y(t-1-r), r >= ny for u(t-nk-(r-ny)); empty = the constant 1.
using NarxTerm = std::vector<int>;

/// Polynomial NARX model y(t) = sum_i theta_i p_i(t) in normalised signals (see above).
struct NarxModel {
  int ny = 1,       ///< output lags y(t-1) .. y(t-ny)
      nu = 1,       ///< input lags u(t-nk) .. u(t-nk-nu+1)
      nk = 1,       ///< input delay in samples
      degree = 2;   ///< largest number of regressors multiplied in one term
  double Ts = 1.0;  ///< sample time, s
  // Normalisation (see above): u enters as (u - u_offset) / u_scale, y as y / y_scale.
  double u_offset = 0.0,  ///< subtracted from the input before u_scale (input units)
      u_scale = 1.0,      ///< divisor of the input after u_offset (input units)
      y_scale = 1.0;      ///< divisor of the output; the model output is multiplied by it
  /// Output band of the free run (output units, see above); infinite = none.
  double y_min = -std::numeric_limits<double>::infinity();
  double y_max = std::numeric_limits<double>::infinity();  ///< upper end of the band
  std::vector<NarxTerm> terms;                             ///< selected monomials, one per theta
  std::vector<double> theta;                               ///< one per term
  std::vector<double> err;  ///< ERR of each term when it was selected (fraction of y'y)
  /// First sample with a complete regressor, max(ny, nk + nu - 1).
  int FirstSample() const;
  /// "1", "y(t-1)", "y(t-2)^2", "u(t-1)*y(t-2)".
  std::string TermName(const NarxTerm& term) const;
  /// "y(t) = 0.5 y(t-1) - 0.16 y(t-2)^2 + ..." with 4 significant digits, in
  /// the normalised signals.
  std::string Equation() const;
  /// One-step-ahead predictions for t >= FirstSample() (the measured output
  /// before); y and u of equal length.
  /// @throws InvalidArgument for lengths that differ.
  Eigen::VectorXd Predict(const Eigen::VectorXd& y, const Eigen::VectorXd& u) const;
  /// Free-run simulation (see above), held within [y_min, y_max]; y supplies
  /// the first FirstSample() outputs.
  /// @throws InvalidArgument for lengths that differ or fewer samples than FirstSample().
  Eigen::VectorXd Simulate(const Eigen::VectorXd& u, const Eigen::VectorXd& y) const;
  /// Whether the free run forgets its initial outputs, as the run of a
  /// model of a stable plant fades its initial state: the runs from y's
  /// first FirstSample() outputs shifted by -shift and +shift stay within
  /// shift / 5 of the run from y's own (`run`, computed when null) over the
  /// second half of the samples after FirstSample(). False when a shifted run
  /// is not finite; true for shift <= 0 or fewer than two such samples.
  /// (A polynomial NARX can fit a record from its measured start and run off
  /// to its output band's edge from a start nearby.)
  /// @throws InvalidArgument as Simulate.
  bool ForgetsItsStart(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double shift,
                       const Eigen::VectorXd* run = nullptr) const;
  /// Value of regressor r (see NarxTerm) at time t, normalised.
  double Regressor(int r, Eigen::Index t, const Eigen::VectorXd& y, const Eigen::VectorXd& u) const;
  /// Value of the monomial `term` at time t (1 for the constant).
  double TermValue(const NarxTerm& term, Eigen::Index t, const Eigen::VectorXd& y,
                   const Eigen::VectorXd& u) const;
  bool operator==(const NarxModel&) const = default;
};

/// The JSON form above.
nlohmann::json ToJson(const NarxModel& m);
/// Inverse of ToJson(const NarxModel&).
/// @throws InvalidArgument naming the missing or malformed key or term.
NarxModel NarxModelFromJson(const nlohmann::json& j);

}  // namespace pneumid
