// Ready-made figures in the style of the paper [1] and of MATLAB's System
// Identification and Control toolboxes, built on the figure API (plot.hpp):
//
//   StepResponseFigure       step responses of models (Fig. 4), optionally with the data
//   ImpulseResponseFigure    impulse responses of models
//   ModelComparisonFigure    measured data and models simulated on its input (Fig. 5)
//   ResidualFigure           residual auto-correlation and input-residual
//                            cross-correlation with confidence bands [2]
//   BodeFigure               magnitude (dB) and phase (deg) against frequency (rad/s)
//   ClosedLoopFigure         set-point, outputs and inputs of closed-loop runs (Fig. 6)
//
// Model simulations against data use deviation variables (SimulateOnData of
// pneumid/identify/step/step_methods.hpp): the model is driven by u(t) - u(0) and
// its output is added to the pre-step output level, which is how a model
// identified from a step test is compared with the test it came from.
//
// [1] A. A. M. Emhemed, R. Mamat, A. A. M. Faudzi, Non-parametric
//     identification techniques for intelligent pneumatic actuator, Jurnal
//     Teknologi 77:20 (2015) 115-119, Figs. 4-6.
// [2] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999,
//     sec. 16.6 (residual analysis): with N samples of white residuals the
//     normalized correlations are asymptotically N(0, 1/N), so the band is
//     +-z_{(1+p)/2} / sqrt(N) for confidence level p.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/step/step_methods.hpp"
#include "pneumid/models/static_map.hpp"
#include "pneumid/lti/transfer_function.hpp"
#include "pneumid/report/plot.hpp"

namespace pneumid {

/// A model with the name it has in a legend.
struct NamedModel {
  /// An unnamed static gain 1 without operating point or covariance.
  NamedModel() = default;
  /// Sets every field (see below); u0_, y0_ NaN: levels taken from the data.
  NamedModel(std::string label_, TransferFunction model_,
             double u0_ = std::numeric_limits<double>::quiet_NaN(),
             double y0_ = std::numeric_limits<double>::quiet_NaN(),
             std::shared_ptr<const IdentifiedModel> identified_ = nullptr)
      : label(std::move(label_)),
        model(std::move(model_)),
        u0(u0_),
        y0(y0_),
        identified(std::move(identified_)) {}

  std::string label;       ///< legend entry, e.g. "FOPDT"
  TransferFunction model;  ///< the linear model drawn (continuous or discrete)
  /// Operating point for simulations on data (IdentifiedModel::u0, y0):
  /// y0 + G (u - u0). NaN (default): the levels before the first input change.
  double u0 = std::numeric_limits<double>::quiet_NaN();
  double y0 = std::numeric_limits<double>::quiet_NaN();  ///< output level of the point (see u0)
  /// The identified model `model` was drawn from, for confidence bands: its
  /// parameter covariance propagated to the response (model_uncertainty.hpp)
  /// in the form of `model` (discrete or continuous). None: no band.
  std::shared_ptr<const IdentifiedModel> identified;
};

/// Labels shared by the figures (with units).
struct SignalLabels {
  std::string time = "Time t [s]";         ///< time axis label
  std::string output = "Force F [N]";      ///< output axis label
  std::string input = "Duty cycle u [%]";  ///< input axis label
};

/// Step (and impulse) figure settings.
struct StepFigureOptions {
  double amplitude = 1.0;  ///< height of the input step (input units)
  double t_final = 0.0;    ///< seconds; 0 = the longest automatic horizon of the models
  double dt = 0.0;         ///< sample interval of continuous responses; 0 = automatic
  std::string title = "Step response";  ///< figure title
  SignalLabels labels;                  ///< axis labels (time and output used)
  /// Confidence band of +-confidence standard deviations (shaded, in the
  /// model's colour, "label ±K sd") around each model with a covariance
  /// (NamedModel::identified); 0 = none (default). Step figures only.
  double confidence = 0.0;
  /// True for a finite non-zero amplitude, finite t_final, dt, confidence >= 0 and at
  /// most 1e7 samples t_final / dt; otherwise false with the reason in *error (if not null).
  bool IsValid(std::string* error) const;
};

/// Responses of each model to a step of `amplitude` at t = 0 (Figure 4). When
/// `data` is given, its output minus y(0) is drawn too (starting at the
/// step time, taken as its first sample).
/// @throws InvalidArgument when `models` is empty or options are invalid.
Figure StepResponseFigure(const std::vector<NamedModel>& models,
                          const StepFigureOptions& options = {}, const Dataset* data = nullptr);

/// Responses of each model to an impulse of area `amplitude` at t = 0 (a
/// discrete impulse of that area for discrete models; drawn as staircases).
/// The options are those of the step figure (set `title`, e.g. "Impulse response").
/// @throws InvalidArgument when `models` is empty or options are invalid.
Figure ImpulseResponseFigure(const std::vector<NamedModel>& models,
                             const StepFigureOptions& options = {});

/// Settings of ModelComparisonFigure.
struct ComparisonFigureOptions {
  std::string title = "Model comparison";  ///< figure title
  SignalLabels labels;                     ///< axis labels
  bool show_input = true;                  ///< second subplot with the input
  bool show_fit = true;                    ///< append "(fit xx.x %)" to each legend label
  int input = 0,                           ///< dataset input channel driving the simulations
      output = 0;                          ///< dataset output channel compared with the models
};

/// Data and models simulated on its input on one time axis (Figure 5);
/// a model with an `identified` nonlinear model (maps, NARX) is simulated
/// as that model.
/// @throws InvalidArgument when `models` is empty, the channels do not exist,
///         or SimulateOnData throws.
Figure ModelComparisonFigure(const Dataset& data, const std::vector<NamedModel>& models,
                             const ComparisonFigureOptions& options = {});

/// A model's static input map, labelled; `normalised` for maps scaled to
/// 0..1 (an input-affine NARX's valve map) rather than in output units.
struct NamedStaticMap {
  std::string label;        ///< legend entry
  StaticMap map;            ///< the map f(u), u in input units
  bool normalised = false;  ///< values scaled to 0..1 (drawn on their own axes)
};

/// The static maps f(u) over their input ranges: maps in output units on one
/// axes, normalised maps on a second when there are both.
/// @throws InvalidArgument when `maps` is empty.
Figure StaticMapFigure(const std::vector<NamedStaticMap>& maps, const SignalLabels& labels = {},
                       const std::string& title = "Static maps");

/// Normalized residual correlations (MATLAB `resid`).
struct ResidualCorrelation {
  Eigen::VectorXd auto_lags;   ///< 0..max_lag
  Eigen::VectorXd autocorr;    ///< r_ee(k) / r_ee(0)
  Eigen::VectorXd cross_lags;  ///< -max_lag..max_lag
  Eigen::VectorXd crosscorr;   ///< r_ue(k) / sqrt(r_ee(0) r_uu(0)), u leading e by k
  double bound = 0.0;          ///< confidence bound z / sqrt(N)
  double confidence = 0.99;    ///< confidence level of `bound`, in (0, 1)
  double auto_outside = 0.0,   ///< fraction of autocorrelation lags k >= 1 outside the bound
      cross_outside = 0.0;     ///< fraction of cross-correlation lags outside the bound
};

/// Residual correlations of residuals e against input u (same length N, with
/// means removed), lags up to max_lag, confidence level in (0, 1).
/// @throws InvalidArgument for sizes that differ, N < max_lag + 2, max_lag < 1,
///         a confidence outside (0, 1) or a constant residual.
ResidualCorrelation ComputeResidualCorrelation(const Eigen::VectorXd& residuals,
                                               const Eigen::VectorXd& input, int max_lag = 25,
                                               double confidence = 0.99);

/// Two subplots: autocorrelation of the residuals and cross-correlation with
/// the input, each with its shaded confidence band.
Figure ResidualFigure(const ResidualCorrelation& corr, const std::string& title = "Residuals");

/// Magnitude (dB) and phase (deg) of each model on a common grid (rad/s);
/// an empty omega chooses 10^-1 .. 10^3 rad/s bounded by the Nyquist frequency
/// of discrete models. `confidence` > 0 adds bands of that many standard
/// deviations of magnitude and phase around models with a covariance (as the
/// step figure's). @throws InvalidArgument when `models` is empty or
/// confidence is negative.
Figure BodeFigure(const std::vector<NamedModel>& models,
                  const Eigen::VectorXd& omega = Eigen::VectorXd(),
                  const std::string& title = "Bode diagram", double confidence = 0.0);

/// One closed-loop run: output y and input u on the common time axis.
struct ClosedLoopTrace {
  std::string label;  ///< legend entry, e.g. the controller
  Eigen::VectorXd y;  ///< output per sample of t (output units, e.g. N)
  Eigen::VectorXd u;  ///< input per sample of t (input units, e.g. duty %)
};

/// Settings of ClosedLoopFigure.
struct ClosedLoopFigureOptions {
  std::string title = "Closed-loop response";  ///< figure title
  SignalLabels labels;                         ///< axis labels
  /// Time at which a load disturbance enters (drawn as a dotted marker line); NaN = none.
  double disturbance_time = std::numeric_limits<double>::quiet_NaN();
};

/// Set-point (dashed), outputs (top) and inputs (bottom, staircases) (Figure 6).
/// @throws InvalidArgument when traces is empty or a length differs from t.
Figure ClosedLoopFigure(const Eigen::VectorXd& t, const Eigen::VectorXd& setpoint,
                        const std::vector<ClosedLoopTrace>& traces,
                        const ClosedLoopFigureOptions& options = {});

}  // namespace pneumid
