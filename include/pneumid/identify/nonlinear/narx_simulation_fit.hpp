// Refinement of a polynomial NARX model's coefficients by its free-run
// simulation error (NarxFocus::kSimulation of narx.hpp), the 'Focus',
// 'simulation' of MATLAB's nlarx for a polynomial regressor set.
//
// The terms stay as given; theta minimises
//   V(theta) = sum_{t >= n0} (s(t) - y(t) / y_scale)^2,
// s the model's free run in normalised signals (s(t) = y(t) / y_scale for
// t < n0, the measured start, as NarxModel::Simulate), by Levenberg-Marquardt
// (Ceres) from the model's theta. The Jacobian follows exactly from the
// sensitivities of the run,
//   ds(t)/dtheta = p(t) + sum_{r < ny} (dv/dy(t-1-r)) ds(t-1-r)/dtheta,
// v(t) = sum_i theta_i p_i(t) and p(t) the term values along the run.
//
// A polynomial free run can leave any bound for a trial theta and overflow;
// to keep V finite the run is clipped to a band around the data,
// [min y - band * range, max y + band * range] (range = max y - min y,
// NarxDataBand), and a clipped sample does not depend on theta. The result
// states whether the model's unclipped run on the data stays inside the band
// (`clipped`, `diverges`; the model's own output band, NarxModel::y_min and
// y_max, which the estimator sets to this band, is not applied there), the
// summary warns when it does not, and when the
// refined model diverges without the band while the start did not, the start
// is kept (termination kNoConvergence, with a warning).
#pragma once

#include <string>
#include <utility>

#include <Eigen/Core>

#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/models/narx_model.hpp"

namespace pneumid {

/// Iteration limit and clip band of FitNarxSimulation.
struct NarxSimulationFitOptions {
  int max_iterations = 100;  ///< most Levenberg-Marquardt iterations (>= 1)
  /// Half-width added on each side of the data range, as a fraction of the
  /// range, within which the run is clipped during the fit (> 0).
  double band = 0.25;
  /// True when max_iterations >= 1 and band > 0 (finite); otherwise false with
  /// the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// The band around the outputs y (above): [min y - band * range, max y +
/// band * range] in output units, range = max y - min y (at least 1e-12 of
/// max(1, |max y|)). y must not be empty.
std::pair<double, double> NarxDataBand(const Eigen::VectorXd& y, double band);

/// Outcome of FitNarxSimulation.
struct NarxSimulationFitResult {
  /// termination of the solve (kNoConvergence at the iteration limit or when
  /// the start was kept; kFailure when the model's unclipped run diverges),
  /// iterations, loss = mean squared unclipped simulation error in output
  /// units (clipped run when the unclipped one is not finite), initial_loss of
  /// the start, message and warnings.
  EstimationSummary summary;
  /// Samples of the model's unclipped run on the data outside the band.
  Eigen::Index clipped = 0;
  /// True when the model's unclipped run on the data is not finite.
  bool diverges = false;
};

/// Refines m->theta (the terms and normalisation kept) by the simulation
/// error on input u and output y (see above); m->theta is the start.
/// @throws InvalidArgument for invalid options, a model without terms, lengths
///         that differ, non-finite data or fewer samples than FirstSample() + 1.
NarxSimulationFitResult FitNarxSimulation(NarxModel* m, const Eigen::VectorXd& u,
                                          const Eigen::VectorXd& y,
                                          const NarxSimulationFitOptions& options = {});

}  // namespace pneumid
