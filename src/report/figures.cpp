#include "pneumid/report/figures.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/evaluation/model_uncertainty.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {

namespace {

// z with P(|Z| <= z) = p for a standard normal Z (bisection on erf).
double TwoSidedNormalQuantile(double p) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (std::erf(mid / std::sqrt(2.0)) < p)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

void CheckModels(const std::vector<NamedModel>& models, const char* what) {
  PNEUMID_CHECK(!models.empty(), "{}: no models to plot", what);
}

// Propagation through the form drawn (discrete or continuous).
UncertaintyOptions FormOf(const NamedModel& m) {
  UncertaintyOptions o;
  o.discrete = m.model.IsDiscrete();
  return o;
}

// The band y +- k sd in the model's colour, when the model has a covariance
// (sd empty otherwise, or NaN where it could not be computed: no band).
void AddConfidenceBand(Axes& ax, const NamedModel& m, const Eigen::VectorXd& x,
                       const Eigen::VectorXd& y, const Eigen::VectorXd& sd, double k, Color c) {
  if (sd.size() != y.size() || !sd.allFinite()) return;
  Band& b = ax.AddBand(x, y - k * sd, y + k * sd, fmt::format("{} \u00b1{:g} sd", m.label, k));
  b.color = c;
  b.alpha = 0.2;
}

}  // namespace

bool StepFigureOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (!std::isfinite(amplitude) || amplitude == 0.0)
    return fail(
        fmt::format("StepFigureOptions::amplitude must be finite and non-zero, got {}", amplitude));
  if (!(t_final >= 0.0) || !std::isfinite(t_final))
    return fail(fmt::format("StepFigureOptions::t_final must be >= 0, got {}", t_final));
  if (!(dt >= 0.0) || !std::isfinite(dt))
    return fail(fmt::format("StepFigureOptions::dt must be >= 0, got {}", dt));
  if (!(confidence >= 0.0) || !std::isfinite(confidence))
    return fail(fmt::format(
        "StepFigureOptions::confidence must be >= 0 standard deviations, got {}", confidence));
  if (t_final > 0.0 && dt > 0.0 && t_final / dt > 1e7)
    return fail(
        fmt::format("StepFigureOptions: t_final / dt = {} samples is too many", t_final / dt));
  return true;
}

namespace {

using ResponseFunction = TimeResponse (*)(const TransferFunction&, double, double);

// The responses `response` (Step or Impulse) of each model, scaled by the amplitude.
Figure ResponseFigure(const char* what, ResponseFunction response,
                      const std::vector<NamedModel>& models, const StepFigureOptions& options,
                      const Dataset* data) {
  CheckModels(models, what);
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "{}", error);
  double t_final = options.t_final;
  if (t_final == 0.0) {
    for (const auto& m : models) {
      const TimeResponse r = response(m.model, 0.0, 0.0);
      if (r.t.size() > 0) t_final = std::max(t_final, r.t[r.t.size() - 1]);
    }
    if (data && data->size() > 1)
      t_final = std::max(t_final, data->time()[data->size() - 1] - data->time()[0]);
  }
  Figure fig(1);
  fig.title = options.title;
  Axes& ax = fig.axes(0);
  ax.xlabel = options.labels.time;
  ax.ylabel = options.labels.output;
  if (data) {
    PNEUMID_CHECK(data->num_outputs() > 0, "{}: the dataset has no output", what);
    const Eigen::VectorXd t = data->time().array() - data->time()[0];
    const Eigen::VectorXd y = data->y(0).array() - data->y(0)[0];
    Curve& s = ax.AddLine(t, y, "measured data");
    s.color = Color{60, 60, 60};
    s.width = 1.2;
  }
  int k = 0;
  for (const auto& m : models) {
    const TimeResponse r = response(m.model, t_final, m.model.IsDiscrete() ? 0.0 : options.dt);
    if (options.confidence > 0.0 && m.identified && response == &Step)
      AddConfidenceBand(
          ax, m, r.t, r.y * options.amplitude,
          StepResponseStd(*m.identified, r.t, FormOf(m)) * std::abs(options.amplitude),
          options.confidence, PaletteColor(k));
    Curve& s = ax.AddLine(r.t, r.y * options.amplitude, m.label);
    s.color = PaletteColor(k++);
    if (m.model.IsDiscrete()) s.stairs = true;
  }
  ax.legend = LegendPosition::kBottomRight;
  return fig;
}

}  // namespace

Figure StepResponseFigure(const std::vector<NamedModel>& models, const StepFigureOptions& options,
                          const Dataset* data) {
  return ResponseFigure("StepResponseFigure", &Step, models, options, data);
}

Figure ImpulseResponseFigure(const std::vector<NamedModel>& models,
                             const StepFigureOptions& options) {
  return ResponseFigure("ImpulseResponseFigure", &Impulse, models, options, nullptr);
}

Figure ModelComparisonFigure(const Dataset& data, const std::vector<NamedModel>& models,
                             const ComparisonFigureOptions& options) {
  CheckModels(models, "ModelComparisonFigure");
  PNEUMID_CHECK(options.input >= 0 && options.input < data.num_inputs(),
                "ModelComparisonFigure: input channel {} does not exist (the data have {})",
                options.input, data.num_inputs());
  PNEUMID_CHECK(options.output >= 0 && options.output < data.num_outputs(),
                "ModelComparisonFigure: output channel {} does not exist (the data have {})",
                options.output, data.num_outputs());
  Figure fig(options.show_input ? 2 : 1);
  fig.title = options.title;
  const Eigen::VectorXd t = data.time();
  const Eigen::VectorXd y = data.y(options.output);
  Axes& ax = fig.axes(0);
  ax.ylabel = options.labels.output;
  if (!options.show_input) ax.xlabel = options.labels.time;
  Curve& meas = ax.AddLine(t, y, "measured data");
  meas.color = Color{60, 60, 60};
  meas.width = 1.2;
  int k = 0;
  const bool fit_defined = (y.array() != y[0]).any();
  for (const auto& m : models) {
    Eigen::VectorXd yhat;
    if (m.identified && IsNonlinearModel(*m.identified)) {
      // The maps and NARX terms, not the linear part alone.
      yhat = SimulateModel(*m.identified, data, options.input);
    } else if (std::isfinite(m.u0) && std::isfinite(m.y0)) {
      IdentifiedModel im;
      im.tf = m.model;
      im.u0 = m.u0;
      im.y0 = m.y0;
      yhat = SimulateModel(im, data, options.input);
    } else {
      yhat = SimulateOnData(m.model, data, options.input, options.output);
    }
    std::string label = m.label;
    if (options.show_fit && fit_defined) label += fmt::format(" (fit {:.1f} %)", NrmseFit(y, yhat));
    Curve& s = ax.AddLine(t, yhat, label, k % 2 == 0 ? LineStyle::kSolid : LineStyle::kDashed);
    s.color = PaletteColor(k++);
  }
  ax.legend = LegendPosition::kBottomRight;
  if (options.show_input) {
    Axes& in = fig.axes(1);
    in.xlabel = options.labels.time;
    in.ylabel = options.labels.input;
    in.AddStairs(t, data.u(options.input), "input");
    in.legend = LegendPosition::kNone;
  }
  return fig;
}

Figure StaticMapFigure(const std::vector<NamedStaticMap>& maps, const SignalLabels& labels,
                       const std::string& title) {
  PNEUMID_CHECK(!maps.empty(), "a static map figure needs at least one map");
  const bool any_normalised =
      std::any_of(maps.begin(), maps.end(), [](const NamedStaticMap& m) { return m.normalised; });
  const bool any_plain =
      std::any_of(maps.begin(), maps.end(), [](const NamedStaticMap& m) { return !m.normalised; });
  Figure fig(any_normalised && any_plain ? 2 : 1);
  fig.title = title;
  int k = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const bool normalised = pass == 1;
    if (normalised ? !any_normalised : !any_plain) continue;
    Axes& ax = fig.axes(normalised && any_plain ? 1 : 0);
    ax.xlabel = labels.input;
    ax.ylabel = normalised ? "f(u) (normalised, 0..1)" : "f(u): " + labels.output;
    for (const NamedStaticMap& m : maps) {
      if (m.normalised != normalised) continue;
      const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(201, m.map.u_min(), m.map.u_max());
      Curve& c = ax.AddLine(u, m.map.Evaluate(u), m.label);
      c.color = PaletteColor(k++);
    }
    ax.legend = LegendPosition::kBottomRight;
  }
  return fig;
}

ResidualCorrelation ComputeResidualCorrelation(const Eigen::VectorXd& residuals,
                                               const Eigen::VectorXd& input, int max_lag,
                                               double confidence) {
  const Eigen::Index n = residuals.size();
  PNEUMID_CHECK(input.size() == n,
                "ComputeResidualCorrelation: residuals and input differ in length ({} vs {})", n,
                input.size());
  PNEUMID_CHECK(max_lag >= 1, "ComputeResidualCorrelation: max_lag must be >= 1, got {}", max_lag);
  PNEUMID_CHECK(n >= max_lag + 2,
                "ComputeResidualCorrelation: {} samples are too few for max_lag = {}", n, max_lag);
  PNEUMID_CHECK(confidence > 0.0 && confidence < 1.0,
                "ComputeResidualCorrelation: confidence must be in (0, 1), got {}", confidence);
  PNEUMID_CHECK(residuals.allFinite() && input.allFinite(),
                "ComputeResidualCorrelation: residuals and input must be finite");
  const Eigen::VectorXd e = residuals.array() - residuals.mean();
  const Eigen::VectorXd u = input.array() - input.mean();
  const double ree0 = e.squaredNorm() / n;
  const double ruu0 = u.squaredNorm() / n;
  PNEUMID_CHECK(ree0 > 0.0, "ComputeResidualCorrelation: the residuals are constant");
  ResidualCorrelation c;
  c.confidence = confidence;
  c.bound = TwoSidedNormalQuantile(confidence) / std::sqrt(static_cast<double>(n));
  c.auto_lags.resize(max_lag + 1);
  c.autocorr.resize(max_lag + 1);
  int outside = 0;
  for (int k = 0; k <= max_lag; ++k) {
    const double r = e.head(n - k).dot(e.tail(n - k)) / n;
    c.auto_lags[k] = k;
    c.autocorr[k] = r / ree0;
    if (k >= 1 && std::abs(c.autocorr[k]) > c.bound) ++outside;
  }
  c.auto_outside = static_cast<double>(outside) / max_lag;
  c.cross_lags.resize(2 * max_lag + 1);
  c.crosscorr.resize(2 * max_lag + 1);
  outside = 0;
  const double scale = ruu0 > 0.0 ? 1.0 / std::sqrt(ree0 * ruu0) : 0.0;
  for (int k = -max_lag; k <= max_lag; ++k) {
    // R_eu(k) = 1/N sum_t e(t + k) u(t)
    double r = 0.0;
    if (k >= 0)
      r = e.tail(n - k).dot(u.head(n - k)) / n;
    else
      r = e.head(n + k).dot(u.tail(n + k)) / n;
    const int i = k + max_lag;
    c.cross_lags[i] = k;
    c.crosscorr[i] = r * scale;
    if (std::abs(c.crosscorr[i]) > c.bound) ++outside;
  }
  c.cross_outside = static_cast<double>(outside) / (2 * max_lag + 1);
  return c;
}

Figure ResidualFigure(const ResidualCorrelation& corr, const std::string& title) {
  Figure fig(2);
  fig.title = title;
  const std::string band = fmt::format("{:g} % confidence", 100.0 * corr.confidence);
  auto draw = [&](Axes& ax, const Eigen::VectorXd& lags, const Eigen::VectorXd& r) {
    const Eigen::VectorXd lo = Eigen::VectorXd::Constant(lags.size(), -corr.bound);
    const Eigen::VectorXd hi = Eigen::VectorXd::Constant(lags.size(), corr.bound);
    ax.AddBand(lags, lo, hi, band);
    ax.AddLine(lags, r, "correlation");
    ax.AddHorizontalLine(0.0, "", LineStyle::kSolid).color = Color{150, 150, 150};
    ax.legend = LegendPosition::kTopRight;
  };
  Axes& a = fig.axes(0);
  a.title = "Autocorrelation of the residuals e";
  a.ylabel = "r#dee#u(k) / r#dee#u(0) [-]";
  a.xlabel = "Lag k [samples]";
  draw(a, corr.auto_lags, corr.autocorr);
  a.ymin = std::min(-1.05 * corr.bound, corr.autocorr.minCoeff() - 0.05);
  a.ymax = 1.05;
  Axes& b = fig.axes(1);
  b.title = "Cross-correlation of input u and residuals e";
  b.ylabel = "r#deu#u(k) normalized [-]";
  b.xlabel = "Lag k [samples]";
  draw(b, corr.cross_lags, corr.crosscorr);
  return fig;
}

Figure BodeFigure(const std::vector<NamedModel>& models, const Eigen::VectorXd& omega,
                  const std::string& title, double confidence) {
  CheckModels(models, "BodeFigure");
  double nyquist = std::numeric_limits<double>::infinity();
  for (const auto& m : models)
    if (m.model.IsDiscrete()) nyquist = std::min(nyquist, M_PI / m.model.Ts());
  Eigen::VectorXd w = omega;
  if (w.size() == 0) {
    double wmin = std::numeric_limits<double>::infinity(), wmax = 0.0;
    for (const auto& m : models) {
      const Eigen::VectorXcd p = m.model.Poles();
      for (Eigen::Index i = 0; i < p.size(); ++i) {
        double mag =
            m.model.IsDiscrete() ? std::abs(std::log(p[i])) / m.model.Ts() : std::abs(p[i]);
        if (std::isfinite(mag) && mag > 1e-9) {
          wmin = std::min(wmin, mag);
          wmax = std::max(wmax, mag);
        }
      }
    }
    double lo = std::isfinite(wmin) ? std::floor(std::log10(wmin)) - 1.0 : -1.0;
    double hi = wmax > 0.0 ? std::ceil(std::log10(wmax)) + 1.0 : 3.0;
    if (std::isfinite(nyquist)) hi = std::min(hi, std::log10(nyquist));
    if (hi <= lo) lo = hi - 2.0;
    w = Eigen::VectorXd::LinSpaced(400, lo, hi).unaryExpr([](double e) {
      return std::pow(10.0, e);
    });
  }
  PNEUMID_CHECK(w.size() >= 2 && (w.array() > 0.0).all(),
                "BodeFigure: omega needs at least 2 positive frequencies");
  PNEUMID_CHECK(confidence >= 0.0 && std::isfinite(confidence),
                "BodeFigure: confidence must be >= 0 standard deviations, got {}", confidence);
  Figure fig(2);
  fig.title = title;
  Axes& mag = fig.axes(0);
  Axes& ph = fig.axes(1);
  mag.log_x = ph.log_x = true;
  mag.ylabel = "Magnitude [dB]";
  ph.ylabel = "Phase [deg]";
  ph.xlabel = "Frequency #gw [rad/s]";
  mag.legend = LegendPosition::kBottomLeft;
  ph.legend = LegendPosition::kNone;
  int k = 0;
  for (const auto& m : models) {
    Eigen::VectorXd wm = w;
    if (m.model.IsDiscrete()) {
      std::vector<double> keep;
      for (Eigen::Index i = 0; i < w.size(); ++i)
        if (w[i] <= M_PI / m.model.Ts() * (1.0 + 1e-12)) keep.push_back(w[i]);
      wm = Eigen::Map<Eigen::VectorXd>(keep.data(), static_cast<Eigen::Index>(keep.size()));
    }
    if (wm.size() < 2) continue;
    // Magnitude in dB and phase unwrapped along the grid (delay included).
    Eigen::VectorXd mag_db(wm.size()), phase(wm.size());
    double prev = 0.0;
    for (Eigen::Index i = 0; i < wm.size(); ++i) {
      const std::complex<double> h = m.model.FrequencyResponse(wm[i]);
      mag_db[i] = 20.0 * std::log10(std::abs(h));
      double p = std::arg(h) * 180.0 / M_PI;
      if (i > 0) p += 360.0 * std::round((prev - p) / 360.0);
      phase[i] = prev = p;
    }
    const Color c = PaletteColor(k);
    if (confidence > 0.0 && m.identified) {
      const BodeStd sd = BodeResponseStd(*m.identified, wm, FormOf(m));
      AddConfidenceBand(mag, m, wm, mag_db, sd.magnitude_db, confidence, c);
      AddConfidenceBand(ph, m, wm, phase, sd.phase_deg, confidence, c);
    }
    const LineStyle style = k % 2 == 0 ? LineStyle::kSolid : LineStyle::kDashed;
    mag.AddLine(wm, mag_db, m.label, style).color = c;
    ph.AddLine(wm, phase, m.label, style).color = c;
    ++k;
  }
  PNEUMID_CHECK(k > 0, "BodeFigure: no model has frequencies below its Nyquist frequency");
  return fig;
}

Figure ClosedLoopFigure(const Eigen::VectorXd& t, const Eigen::VectorXd& setpoint,
                        const std::vector<ClosedLoopTrace>& traces,
                        const ClosedLoopFigureOptions& options) {
  PNEUMID_CHECK(!traces.empty(), "ClosedLoopFigure: no closed-loop runs to plot");
  PNEUMID_CHECK(t.size() >= 2, "ClosedLoopFigure: need at least 2 samples, got {}", t.size());
  PNEUMID_CHECK(setpoint.size() == t.size(),
                "ClosedLoopFigure: set-point has {} samples, time has {}", setpoint.size(),
                t.size());
  for (const auto& tr : traces) {
    PNEUMID_CHECK(tr.y.size() == t.size() && tr.u.size() == t.size(),
                  "ClosedLoopFigure: run '{}' has {} outputs and {} inputs for {} time samples",
                  tr.label, tr.y.size(), tr.u.size(), t.size());
  }
  Figure fig(2);
  fig.title = options.title;
  Axes& out = fig.axes(0);
  Axes& in = fig.axes(1);
  out.ylabel = options.labels.output;
  in.ylabel = options.labels.input;
  in.xlabel = options.labels.time;
  Curve& sp = out.AddStairs(t, setpoint, "set-point");
  sp.style = LineStyle::kDashed;
  sp.color = Color{40, 40, 40};
  sp.width = 1.5;
  int k = 0;
  for (const auto& tr : traces) {
    const Color c = PaletteColor(k++);
    // Alternate solid and dashed lines so that runs that nearly coincide stay
    // distinguishable.
    const LineStyle style = k % 2 == 1 ? LineStyle::kSolid : LineStyle::kDashed;
    Curve& so = out.AddLine(t, tr.y, tr.label, style);
    so.color = c;
    Curve& s = in.AddStairs(t, tr.u, tr.label);
    s.color = c;
    s.style = style;
  }
  if (std::isfinite(options.disturbance_time)) {
    for (Axes* ax : {&out, &in}) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const auto& s : ax->series) {
        lo = std::min(lo, s.y.minCoeff());
        hi = std::max(hi, s.y.maxCoeff());
      }
      Curve& d = ax->AddLine(Eigen::Vector2d(options.disturbance_time, options.disturbance_time),
                             Eigen::Vector2d(lo, hi), ax == &out ? "load disturbance" : "",
                             LineStyle::kDotted);
      d.color = Color{120, 120, 120};
      d.width = 1.2;
    }
  }
  out.legend = LegendPosition::kBottomRight;
  in.legend = LegendPosition::kTopRight;
  return fig;
}

}  // namespace pneumid
