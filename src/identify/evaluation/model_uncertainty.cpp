#include "pneumid/identify/evaluation/model_uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <map>
#include <variant>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/identify/parametric/process_model.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool IsPolynomialStructure(const std::string& s) {
  return s == "ARX" || s == "ARMAX" || s == "OE" || s == "BJ" || s == "IV4";
}

// Where each process parameter name goes in ProcessParams.
double ProcessParams::*ProcessMember(const std::string& name) {
  static const std::map<std::string, double ProcessParams::*> members = {
      {"K", &ProcessParams::K},         {"tau", &ProcessParams::T1},
      {"tau1", &ProcessParams::T1},     {"tau2", &ProcessParams::T2},
      {"tau3", &ProcessParams::T3},     {"Tw", &ProcessParams::Tw},
      {"zeta", &ProcessParams::zeta},   {"Tz", &ProcessParams::Tz},
      {"theta", &ProcessParams::theta}, {"y0", &ProcessParams::y0}};
  const auto it = members.find(name);
  return it == members.end() ? nullptr : it->second;
}

// Rebuilds the transfer function of an identified model from the parameters
// named by its covariance.
class Rebuilder {
 public:
  Rebuilder(const IdentifiedModel& m, bool discrete) {
    PNEUMID_CHECK(m.covariance.has_value(), "model '{}' has no parameter covariance", m.method);
    const ParameterCovariance& c = *m.covariance;
    const auto n = static_cast<Eigen::Index>(c.names.size());
    PNEUMID_CHECK(n > 0 && c.matrix.rows() == n && c.matrix.cols() == n,
                  "model '{}': covariance of {} x {} for {} parameter names", m.method,
                  c.matrix.rows(), c.matrix.cols(), n);
    PNEUMID_CHECK(c.matrix.allFinite(), "model '{}': the covariance is not finite", m.method);
    if (IsPolynomialStructure(m.structure)) {
      poly_ = PolynomialModelFromParams(m.params, m.structure);
      const std::vector<std::string> names = poly_->ParameterNames();
      base_ = poly_->Parameters();
      for (const std::string& name : c.names) {
        const auto it = std::find(names.begin(), names.end(), name);
        PNEUMID_CHECK(it != names.end(), "model '{}': covariance parameter '{}' is not one of {}",
                      m.method, name, fmt::join(names, ", "));
        index_.push_back(static_cast<Eigen::Index>(it - names.begin()));
      }
      // The form drawn: discrete when asked or when no continuous form exists.
      discrete_ = discrete || m.tf.IsDiscrete();
      tustin_ = !discrete_ && m.discrete && !IsZohForm(m);
    } else {
      bool zero = false;
      structure_ = m.structure == "FOPDT" ? ProcessStructure::kP1D
                                          : ProcessStructureFromString(m.structure, &zero);
      zero_ = zero;
      for (const auto& [name, value] : m.params) {
        if (double ProcessParams::*p = ProcessMember(name)) {
          process_.*p = m.params.Scalar(name);
        }
      }
      for (const std::string& name : c.names) {
        PNEUMID_CHECK(ProcessMember(name) != nullptr && m.params.contains(name),
                      "model '{}': covariance parameter '{}' is not a parameter of the {} model",
                      m.method, name, m.structure);
      }
      names_ = c.names;
    }
  }

  Eigen::VectorXd Nominal(const IdentifiedModel& m) const {
    Eigen::VectorXd theta(static_cast<Eigen::Index>(m.covariance->names.size()));
    for (Eigen::Index i = 0; i < theta.size(); ++i) {
      theta[i] = poly_ ? base_[index_[static_cast<std::size_t>(i)]]
                       : m.params.Scalar(m.covariance->names[static_cast<std::size_t>(i)]);
    }
    return theta;
  }

  TransferFunction Build(const Eigen::VectorXd& theta) const {
    if (!poly_) {
      ProcessParams p = process_;
      for (std::size_t i = 0; i < names_.size(); ++i)
        p.*ProcessMember(names_[i]) = theta[static_cast<Eigen::Index>(i)];
      return ProcessTransferFunction(structure_, zero_, p);
    }
    Eigen::VectorXd full = base_;
    for (std::size_t i = 0; i < index_.size(); ++i)
      full[index_[i]] = theta[static_cast<Eigen::Index>(i)];
    const TransferFunction g = SetParameters(full).ToTransferFunction(0);
    if (discrete_) return g;
    return D2C(g, tustin_ ? DiscretizationMethod::kTustin : DiscretizationMethod::kZoh);
  }

 private:
  // Whether the stored continuous form is the zoh one (else it came from tustin).
  static bool IsZohForm(const IdentifiedModel& m) {
    for (const std::string& note : m.notes)
      if (note.rfind("continuous form by tustin", 0) == 0) return false;
    return true;
  }

  // The polynomial model with its free parameters (ParameterNames order) set to p.
  PolynomialModel SetParameters(const Eigen::VectorXd& p) const {
    PolynomialModel m = *poly_;
    Eigen::Index k = 0;
    for (int i = 1; i <= m.na(); ++i) m.a[i] = p[k++];
    for (int in = 0; in < m.num_inputs(); ++in)
      for (int i = 0; i < m.nb(in); ++i) m.b[in][m.nk[in] + i] = p[k++];
    for (int i = 1; i <= m.nc(); ++i) m.c[i] = p[k++];
    for (int i = 1; i <= m.nd(); ++i) m.d[i] = p[k++];
    for (int in = 0; in < m.num_inputs(); ++in)
      for (int i = 1; i <= m.nf(in); ++i) m.f[in][i] = p[k++];
    return m;
  }

  std::optional<PolynomialModel> poly_;
  Eigen::VectorXd base_;
  std::vector<Eigen::Index> index_;
  bool discrete_ = false;
  bool tustin_ = false;
  ProcessStructure structure_ = ProcessStructure::kP1D;
  bool zero_ = false;
  ProcessParams process_;
  std::vector<std::string> names_;
};

// sd_k = sqrt(J_k P J_k^T) of the rows of the sensitivities J, where column i
// of J is difference(response(theta + h_i e_i), response(theta - h_i e_i)) / (2 h_i),
// or the one-sided difference with the nominal response when the model cannot
// be built on one side (a parameter at its bound, e.g. a delay of 0).
// NaN everywhere when it cannot be built on either side or not evaluated.
template <typename Response, typename Difference>
Eigen::MatrixXd PropagatedStd(const IdentifiedModel& model, const UncertaintyOptions& options,
                              Eigen::Index rows, int outputs, Response response,
                              Difference difference) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "{}", error);
  const Rebuilder rebuild(model, options.discrete);
  const Eigen::MatrixXd& P = model.covariance->matrix;
  const Eigen::VectorXd theta = rebuild.Nominal(model);
  const Eigen::Index np = theta.size();
  using Value = decltype(response(rebuild.Build(theta)));
  // The response at theta + step e_i, nothing when that model cannot be built.
  auto at = [&](Eigen::Index i, double step) -> std::optional<Value> {
    Eigen::VectorXd p = theta;
    p[i] += step;
    std::optional<TransferFunction> g;
    try {
      g = rebuild.Build(p);
    } catch (const InvalidArgument&) {
      return std::nullopt;
    }
    return response(*g);
  };
  std::vector<Eigen::MatrixXd> J(static_cast<std::size_t>(outputs),
                                 Eigen::MatrixXd::Zero(rows, np));
  try {
    std::optional<Value> nominal;
    for (Eigen::Index i = 0; i < np; ++i) {
      const double h =
          options.relative_step * std::max(std::abs(theta[i]), std::sqrt(std::max(P(i, i), 0.0)));
      if (!(h > 0.0)) continue;  // a parameter known exactly (P_ii = 0 and theta_i = 0)
      std::optional<Value> up = at(i, h), down = at(i, -h);
      if (!up && !down) return Eigen::MatrixXd::Constant(rows, outputs, kNaN);
      double width = 2.0 * h;
      if (!up || !down) {
        if (!nominal) nominal = response(rebuild.Build(theta));
        (up ? down : up) = nominal;
        width = h;
      }
      for (int o = 0; o < outputs; ++o)
        J[static_cast<std::size_t>(o)].col(i) = difference(*up, *down, o) / width;
    }
  } catch (const InvalidArgument&) {
    return Eigen::MatrixXd::Constant(rows, outputs, kNaN);
  }
  Eigen::MatrixXd sd(rows, outputs);
  for (int o = 0; o < outputs; ++o) {
    const Eigen::MatrixXd& Jo = J[static_cast<std::size_t>(o)];
    sd.col(o) = (Jo * P).cwiseProduct(Jo).rowwise().sum().cwiseMax(0.0).cwiseSqrt();
  }
  return sd;
}

}  // namespace

bool UncertaintyOptions::IsValid(std::string* error) const {
  if (!(relative_step > 0.0 && relative_step <= 0.1)) {
    if (error)
      *error = fmt::format("UncertaintyOptions::relative_step must be in (0, 0.1], got {}",
                           relative_step);
    return false;
  }
  return true;
}

bool HasCovariance(const IdentifiedModel& model) {
  if (!model.covariance) return false;
  try {
    const Rebuilder r(model, false);
    return true;
  } catch (const InvalidArgument&) {
    return false;
  }
}

Eigen::VectorXd CovarianceParameters(const IdentifiedModel& model) {
  return Rebuilder(model, false).Nominal(model);
}

TransferFunction ModelWithParameters(const IdentifiedModel& model, const Eigen::VectorXd& theta,
                                     const UncertaintyOptions& options) {
  const Rebuilder r(model, options.discrete);
  PNEUMID_CHECK(theta.size() == static_cast<Eigen::Index>(model.covariance->names.size()),
                "model '{}': {} parameter values for {} covariance parameters", model.method,
                theta.size(), model.covariance->names.size());
  return r.Build(theta);
}

Eigen::VectorXd StepResponseAt(const TransferFunction& g, const Eigen::VectorXd& t) {
  PNEUMID_CHECK(t.allFinite() && (t.array() >= 0.0).all(),
                "StepResponseAt: times must be finite and >= 0");
  if (t.size() == 0) return {};
  const double t_max = t.maxCoeff();
  if (g.IsDiscrete()) {
    const double Ts = g.Ts();
    const auto n = static_cast<Eigen::Index>(std::floor(t_max / Ts + 1e-9)) + 1;
    const Eigen::VectorXd y = Lsim(g, Eigen::VectorXd::Ones(n), Ts);
    Eigen::VectorXd out(t.size());
    for (Eigen::Index k = 0; k < t.size(); ++k)
      out[k] = y[std::min(n - 1, static_cast<Eigen::Index>(std::floor(t[k] / Ts + 1e-9)))];
    return out;
  }
  // A uniform grid from 0 is simulated directly (exact); others are interpolated.
  const Eigen::Index n = t.size();
  const double dt = n > 1 ? t[1] - t[0] : 0.0;
  bool uniform = n > 1 && t[0] == 0.0 && dt > 0.0;
  for (Eigen::Index k = 0; uniform && k < n; ++k)
    uniform = std::abs(t[k] - static_cast<double>(k) * dt) <= 1e-9 * std::max(1.0, t_max);
  if (uniform) return Lsim(g, Eigen::VectorXd::Ones(n), dt);
  if (t_max == 0.0) return Eigen::VectorXd::Constant(n, Lsim(g, Eigen::VectorXd::Ones(1), 1.0)[0]);
  const Eigen::Index m = 4001;
  const double h = t_max / static_cast<double>(m - 1);
  const Eigen::VectorXd y = Lsim(g, Eigen::VectorXd::Ones(m), h);
  Eigen::VectorXd out(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double x = t[k] / h;
    const auto i = std::min<Eigen::Index>(m - 2, static_cast<Eigen::Index>(std::floor(x)));
    const double f = x - static_cast<double>(i);
    out[k] = (1.0 - f) * y[i] + f * y[i + 1];
  }
  return out;
}

Eigen::VectorXd StepResponseStd(const IdentifiedModel& model, const Eigen::VectorXd& t,
                                const UncertaintyOptions& options) {
  PNEUMID_CHECK(t.allFinite() && (t.array() >= 0.0).all(),
                "StepResponseStd: times must be finite and >= 0");
  if (!HasCovariance(model)) return {};
  return PropagatedStd(
      model, options, t.size(), 1, [&t](const TransferFunction& g) { return StepResponseAt(g, t); },
      [](const Eigen::VectorXd& a, const Eigen::VectorXd& b, int) -> Eigen::VectorXd {
        return a - b;
      });
}

BodeStd BodeResponseStd(const IdentifiedModel& model, const Eigen::VectorXd& w,
                        const UncertaintyOptions& options) {
  PNEUMID_CHECK(w.allFinite() && (w.array() > 0.0).all(),
                "BodeResponseStd: frequencies must be finite and > 0");
  if (!HasCovariance(model)) return {};
  const Eigen::MatrixXd sd = PropagatedStd(
      model, options, w.size(), 2,
      [&w](const TransferFunction& g) {
        if (g.IsDiscrete())
          PNEUMID_CHECK(w.maxCoeff() <= M_PI / g.Ts() * (1.0 + 1e-12),
                        "BodeResponseStd: frequency {} rad/s above the Nyquist frequency {} rad/s",
                        w.maxCoeff(), M_PI / g.Ts());
        Eigen::VectorXcd h(w.size());
        for (Eigen::Index k = 0; k < w.size(); ++k) h[k] = g.FrequencyResponse(w[k]);
        return h;
      },
      [](const Eigen::VectorXcd& a, const Eigen::VectorXcd& b, int o) -> Eigen::VectorXd {
        Eigen::VectorXd d(a.size());
        for (Eigen::Index k = 0; k < a.size(); ++k) {
          const std::complex<double> ratio = a[k] / b[k];
          d[k] = o == 0 ? 20.0 * std::log10(std::abs(ratio)) : std::arg(ratio) * 180.0 / M_PI;
        }
        return d;
      });
  return {sd.col(0), sd.col(1)};
}

void SetDiagonalCovariance(IdentifiedModel* model, const std::vector<std::string>& names) {
  ParameterCovariance c;
  std::vector<double> var;
  for (const std::string& name : names) {
    const std::optional<double> sd = model->param_std.FindScalar(name);
    if (!sd || !std::isfinite(*sd)) continue;
    c.names.push_back(name);
    var.push_back(*sd * *sd);
  }
  if (c.names.empty()) return;
  c.matrix = Eigen::Map<const Eigen::VectorXd>(var.data(), static_cast<Eigen::Index>(var.size()))
                 .asDiagonal();
  model->covariance = std::move(c);
}

}  // namespace pneumid
