// Block-oriented nonlinear models: static maps and linear dynamics in series
// ([1] sec. 5.5, [2]). Methods `hammerstein`, `wiener` and `hw` of
// `pneumid identify`.
//
//   Hammerstein:         v(t) = f(u(t)),  y(t) = G(q) v(t) + e(t)
//   Wiener:              x(t) = G(q) u(t),  y(t) = f(x(t)) + e(t)
//   Hammerstein-Wiener:  x(t) = G(q) f(u(t)),  y(t) = g(x(t)) + e(t)
//
// with f a piecewise-linear StaticMap (models/static_map.hpp) through knots
// c_1 < ... < c_m (given, or placed where the data are: PlaceMapKnots) and
//   G(q) = B(q) / A(q) = (b_1 q^-nk + ... + b_nb q^-(nk+nb-1)) / (1 + a_1 q^-1 + ... + a_na q^-na).
//
// Normalisation: the product of the two blocks leaves one scale free
// (G / s and s f give the same model). It is fixed by a linear part of unit
// static gain, G(1) = B(1) / A(1) = 1, so f is the plant's steady-state map in
// output units (Hammerstein) or in input units on the input side (Wiener:
// x has the units of u and f maps it to the output). In the estimation b_nb is
// not free but b_nb = A(1) - (b_1 + ... + b_{nb-1}).
//
// Simulation (SimulateHammerstein / SimulateWiener, used by `validate`): the
// linear part starts in steady state at the first input sample, i.e. the
// record is assumed to start at rest: yhat = f(u(0)) + G (f(u) - f(u(0)))
// (Hammerstein), x = u(0) + G (u - u(0)), yhat = f(x) (Wiener).
//
// Hammerstein estimation:
//   1. over-parameterisation (Bai [3]): with the tent basis h_j of the knots
//      (f(u) = sum_j alpha_j h_j(u), sum_j h_j = 1 inside the knots)
//        f(u) = alpha_1 + sum_{j>=2} d_j h_j(u),  d_j = alpha_j - alpha_1,
//      the ARX form A(q) y = B(q) f(u) + e is linear in a_i, the constant
//      B(1) alpha_1 and the products theta_kj = b_k d_j:
//        y(t) = -sum a_i y(t-i) + c0 + sum_k sum_{j>=2} theta_kj h_j(u(t-nk-k+1)) + e(t),
//      solved by least squares (minimum norm when rank deficient); the
//      rank-1 approximation Theta ~ sigma_1 p q' (SVD) gives b = sigma_1 p,
//      d = q, alpha_1 = c0 / B(1); then scaled to G(1) = 1;
//   2. output-error refinement (Ljung [1] sec. 4.3, [2]): the simulation
//      error sum_t (y(t) - yhat(t))^2 over a, b and alpha is minimised with
//      Levenberg-Marquardt (Ceres, automatic derivatives through the
//      simulation), from the estimate of step 1.
// Wiener estimation: an ARX model (orders na, nb, nk) scaled to G(1) = 1
// gives x; f is the least-squares piecewise-linear fit of y on x (knots where
// the input dwells, widened to the range of x); then the same output-error
// refinement over a, b and the values of f. Placed knots (not given ones)
// end at the range of the final x on the estimation data: an end knot
// beyond it (from the start's wider x) moves to the range's end with f's
// value there, so f is unchanged where the data put x and flat beyond,
// not held at an end value that a few samples at a tent's far edge set.
//
// Hammerstein-Wiener: f (the input map, knots as above) and g (the output
// map, as many knots spread evenly over the range of x = G f(u) at the start,
// empty ones dropped, ending at the final x's range as the Wiener map)
// leave, besides the scale of G, an affine transformation of the
// intermediate signal free (x -> s x + d with f -> s f + d and
// g(x) -> g((x - d) / s) give the same model). It is fixed by
//   G(1) = 1,  f(c_1) = c_1,  f(c_m) = c_m,
// i.e. the input map's end values equal its end knots, so x has the units of
// u (and the model needs f(c_1) != f(c_m): an input map that changes over the
// input range). The free parameters are a, b_1..b_{nb-1}, f(c_2), ..,
// f(c_{m-1}) and the values of g. Start: the Hammerstein estimate (f_H, G),
// moved to f = c_1 + (c_m - c_1) (f_H - f_H(c_1)) / (f_H(c_m) - f_H(c_1));
// g is the least-squares piecewise-linear fit of y on x = G f(u); then the
// output-error refinement over all parameters jointly. `monotone_map` applies
// to `hammerstein` only (the Hammerstein-Wiener maps are not constrained).
// Simulation: yhat = g(f(u(0)) + G (f(u) - f(u(0)))), i.e. SimulateWiener on
// the mapped input f(u).
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
// [2] F. Giri, E.-W. Bai (eds.), Block-oriented Nonlinear System
//     Identification, Springer, 2010.
// [3] E.-W. Bai, An optimal two-stage identification algorithm for
//     Hammerstein-Wiener nonlinear systems, Automatica 34 (1998) 333-338.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/lti/transfer_function.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid {

/// Orders, map knots and refinement settings of the Hammerstein, Wiener and
/// Hammerstein-Wiener estimators.
struct BlockModelOptions {
  int na = 2;  ///< A coefficients (>= 0)
  int nb = 2;  ///< B coefficients (>= 1)
  int nk = 1;  ///< input delay in samples (>= 0)
  /// Knots of the static map (strictly increasing); empty: placed by
  /// PlaceMapKnots(u, num_knots) (static_map_fit.hpp).
  std::vector<double> knots;
  /// Used when `knots` is empty: 0 (default) = where the data are (the levels
  /// of a staircase or multi-level input, else 11 quantiles of u); >= 2 = that
  /// many spread evenly over [min u, max u].
  int num_knots = 0;
  /// Hammerstein only (not Hammerstein-Wiener): keep f monotone (non-decreasing or non-increasing,
  /// the direction of the initial estimate's trend) for an invertible map: the start is made
  /// monotone by PAVA and the refinement runs over alpha_1 and the square roots of the increments,
  /// alpha_j = alpha_{j-1} +- q_j^2.
  bool monotone_map = false;
  /// Output-error refinement with Ceres after the initial estimate.
  bool refine = true;
  int max_iterations = 100;            ///< Levenberg-Marquardt iterations (>= 1)
  double function_tolerance = 1e-10;   ///< Ceres' relative cost change to stop
  double gradient_tolerance = 1e-12;   ///< Ceres' gradient tolerance to stop (> 0)
  double parameter_tolerance = 1e-10;  ///< Ceres' relative parameter step to stop (> 0)
  /// True when na >= 0, nb >= 1, nk >= 0, num_knots is 0 or >= 2, given knots are >= 2,
  /// finite and strictly increasing, max_iterations >= 1 and the tolerances positive;
  /// otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// A static map and a linear part G of unit static gain (see above).
struct BlockModelResult {
  StaticMap map;  ///< f: the input map (Hammerstein, Hammerstein-Wiener) or output map (Wiener)
  /// Hammerstein-Wiener only: the output map g (`map` is then the input map f).
  std::optional<StaticMap> output_map;
  PolynomialModel linear;  ///< structure "OE": a, b (nk leading zeros), nk, Ts
  /// termination, iterations, loss = mean squared simulation error (initial
  /// estimate: initial_loss), warnings (knots without data, ...).
  EstimationSummary summary;
};

/// Hammerstein model of input u and output y sampled every Ts seconds.
/// @throws InvalidArgument for invalid options, signals of different or too
///         short length (fewer samples than 2 x parameters), non-finite
///         values, an input that never leaves one operating point, or knots
///         not strictly increasing.
BlockModelResult EstimateHammerstein(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                     const BlockModelOptions& options = {});

/// Wiener model; errors as EstimateHammerstein.
BlockModelResult EstimateWiener(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                const BlockModelOptions& options = {});

/// Hammerstein-Wiener model y = g(G f(u)) normalised as above; errors as
/// EstimateHammerstein, and for an initial input map with equal end values.
BlockModelResult EstimateHammersteinWiener(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                                           double Ts, const BlockModelOptions& options = {});

/// yhat = f(u(0)) + G (f(u) - f(u(0))), G discrete, started at rest.
/// @throws InvalidArgument for a continuous G.
Eigen::VectorXd SimulateHammerstein(const StaticMap& f, const TransferFunction& g,
                                    const Eigen::VectorXd& u);

/// yhat = f(u(0) G(1) + G (u - u(0))), G discrete, started at rest.
/// @throws InvalidArgument for a continuous G.
Eigen::VectorXd SimulateWiener(const TransferFunction& g, const StaticMap& f,
                               const Eigen::VectorXd& u);

}  // namespace pneumid
