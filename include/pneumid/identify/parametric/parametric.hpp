// Entry point of the parametric and non-parametric black-box estimators for
// `pneumid identify --method M` and the bindings:
//
//   arx    least squares through QR (arx.hpp)         ARX(na, nb, nk)
//   iv4    four-stage instrumental variables (iv.hpp)  ARX structure (na, nb, nk)
//   armax  prediction-error method (pem.hpp)          ARMAX(na, nb, nc, nk)
//   oe     prediction-error method (pem.hpp)          OE(nb, nf, nk)
//   bj     prediction-error method (pem.hpp)          BJ(nb, nc, nd, nf, nk)
//   n4sid  subspace identification (subspace.hpp)     state space of order na
//   cra    correlation analysis with prewhitening (cra.hpp): impulse response
//   spa    spectral analysis, Hann lag window (nonparametric_freq.hpp)
//
// Every result is an IdentifiedModel (identified_model.hpp). For the polynomial
// models `params` holds {"a", "b", "nk", "Ts"} (plus "c", "d", "f" when present;
// b with its nk leading zeros, as MATLAB's idpoly), `discrete` the model
// B/(A F) in z^-1 and `tf` its zero-order-hold continuous equivalent (d2c) when
// it exists (no pole on the closed negative real axis), the discrete model
// otherwise (with a note). `fit_percent` and `iae` are those of the simulated
// (noise-free) model output against the data.
#pragma once

#include <string>
#include <vector>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"

namespace pneumid {

/// The method names handled by IdentifyParametric, in the order above.
const std::vector<std::string>& ParametricMethodNames();

/// True when `name` is one of ParametricMethodNames().
bool IsParametricMethod(const std::string& name);

/// The test of OperatingPointKind::kAuto (identified_model.hpp): the means of
/// u and y over the first max(1, min(20, N / 50)) samples lie within 5 % of
/// their ranges of 0 (a step test from rest, as the paper's).
bool StartsAtRestAtZero(const Eigen::VectorXd& u, const Eigen::VectorXd& y);

/// Identifies input column request.input -> output column request.output of
/// `data` with `method` (see above); orders from request (na, nb, nk, nc, nd, nf).
/// @throws InvalidArgument for an unknown method or invalid orders.
/// @throws DataError when the data are too short or not uniformly sampled.
IdentifiedModel IdentifyParametric(const std::string& method, const Dataset& data,
                                   const IdentifyRequest& request);

/// Wraps an estimated polynomial model into an IdentifiedModel: params,
/// param_std, discrete and continuous forms, fit and IAE of its simulation on
/// `data` (input `input`, output `output`), and the summary's warnings as notes.
IdentifiedModel ToIdentifiedModel(const std::string& method, const PolynomialModel& model,
                                  const EstimationSummary& summary, const Dataset& data,
                                  int input = 0, int output = 0);

}  // namespace pneumid
