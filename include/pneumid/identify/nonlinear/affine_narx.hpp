// Input-affine first-order NARX with a static input map, method `affine-narx`
// of `pneumid identify`: the model of a chamber filled and vented through
// on/off valves.
//
// Model (normalised output z = y / y_scale):
//   z(t) = z(t-1) + a(z(t-1)) + f(u(t-nk)) b(z(t-1)) + e(t),
//   a(z) = sum_{p=0..d} a_p z^p,   b(z) = sum_{p=0..d} b_p z^p,
// with f a piecewise-linear StaticMap through knots spread over the input
// range (as the Hammerstein map, hammerstein.hpp). Physics behind it: the
// mass balance of a chamber whose valve is open a fraction phi of the time,
//   dp/dt = (kappa R T / V) [phi q_in(p) - (1 - phi) q_out(p)]
//         = -c q_out(p) + phi c (q_in(p) + q_out(p)),
// is affine in the open fraction phi = f(duty) (dead band and saturation of
// the valve timing) with state-dependent coefficients (choked and subsonic
// flow); the force is affine in p. Filling and venting therefore run at
// different speeds, which no single static map with one linear part
// (Hammerstein, Wiener) represents.
//
// Estimation: separable (bilinear) least squares on the one-step errors,
// alternating as Narendra and Gallman's iteration for Hammerstein models [1]:
//   1. f fixed: a, b by linear least squares on [z^p, f z^p];
//   2. a, b fixed: the knot values of f by least squares on b(z) h_j(u),
//      h_j the tent basis of the knots (minimum-norm for knots without data);
//      then f is normalised to f(first knot) = 0 and f(last knot) = 1 (the
//      scale and offset of f trade with a and b);
// from f(u) linear in u, until the loss decreases by less than `tolerance`
// relatively or after `max_iterations` rounds. Each step cannot increase the
// loss, so the iteration converges in the loss (to a stationary point).
//
// The result is written as a NARX model (narx.hpp) in the mapped input
// v = f(u): ny = nu = 1, terms z(t-1)^p and v(t-nk) z(t-1)^p, with the 1 of
// z(t-1) folded into its coefficient, plus the map as the model's input_map;
// SimulateNonlinear (nonlinear.hpp) runs v = f(u) then the NARX. ERR of each
// term is its share of z'z in the order written (Gram-Schmidt).
//
// [1] K. S. Narendra, P. G. Gallman, An iterative method for the
//     identification of nonlinear systems using a Hammerstein model, IEEE
//     Trans. Automatic Control 11 (1966) 546-550.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/identify/nonlinear/narx.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid {

/// Settings of EstimateAffineNarx: polynomial degree, delay, knots of the input map f
/// and the stopping rule of the alternating least squares.
struct AffineNarxOptions {
  int degree = 2;  ///< degree d of a(z) and b(z), 1..3
  int nk = 1;      ///< input delay in samples (>= 0; 0: u(t) acts on z(t))
  /// Knots of f (strictly increasing); empty: PlaceMapKnots(u, num_knots)
  /// (static_map_fit.hpp).
  std::vector<double> knots;
  /// Used when `knots` is empty: 0 (default) = where the data are (the levels
  /// of a staircase or multi-level input, else 11 quantiles); >= 2 = that many
  /// spread evenly over the input range.
  int num_knots = 0;
  /// Rounds of the alternating least squares (>= 1). Each round is two small
  /// least-squares solves; the alternation is slow (about 150 rounds on the
  /// IPA twin's staircase), so the limit is high enough that stopping on it
  /// means the loss is still falling.
  int max_iterations = 1000;
  double tolerance = 1e-9;  ///< relative decrease of the loss that ends the iteration
  /// True when degree is 1..3, nk >= 0, num_knots is 0 or >= 2, given knots are >= 2, finite
  /// and strictly increasing, max_iterations >= 1 and tolerance in (0, 1); otherwise false
  /// with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Input-affine NARX estimated by EstimateAffineNarx: the NARX part, the input map and fits.
struct AffineNarxResult {
  NarxModel narx;  ///< in the mapped input v = f(u) (see above)
  StaticMap map;   ///< f, clamped beyond its knots
  /// termination (kConvergence, or kNoConvergence after max_iterations),
  /// iterations, loss (mean squared one-step error in output units^2),
  /// initial_loss (f linear), warnings (knots without data, an unstable
  /// simulation).
  EstimationSummary summary;
  double one_step_fit_percent = 0.0;    ///< NRMSE fit of the one-step predictions
  double simulation_fit_percent = 0.0;  ///< NRMSE fit of the free-run simulation
};

/// Input-affine NARX of input u and output y sampled every Ts seconds.
/// @throws InvalidArgument for invalid options, lengths that differ,
///         non-finite values, an output that is zero throughout, an input that
///         never leaves one operating point, or fewer rows than parameters
///         (naming both numbers).
AffineNarxResult EstimateAffineNarx(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                    const AffineNarxOptions& options = {});

}  // namespace pneumid
