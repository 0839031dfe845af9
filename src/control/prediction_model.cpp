#include "pneumid/control/prediction_model.hpp"

#include <algorithm>
#include <cmath>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {

namespace {

// The one discretization of a design: the zoh discretization of the
// controllable canonical realization of a continuous model (what C2D of the
// transfer function computes before converting back), the realization of a
// discrete one at its own Ts.
StateSpace SampleStateSpace(const TransferFunction& model, double Ts) {
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  if (model.IsContinuous()) return C2D(ToStateSpace(model), Ts, DiscretizationMethod::kZoh);
  PNEUMID_CHECK(std::abs(model.Ts() - Ts) <= 1e-9 * Ts,
                "the discrete model has Ts = {} s but the controller runs at Ts = {} s", model.Ts(),
                Ts);
  return ToStateSpace(model);
}

}  // namespace

PredictionModel::PredictionModel(const TransferFunction& model, double Ts)
    : model_(model),
      sampled_state_space_(SampleStateSpace(model, Ts)),
      sampled_(model.IsContinuous() ? ToTransferFunction(sampled_state_space_) : model),
      Ts_(Ts) {
  PNEUMID_CHECK(sampled_.den().size() > 0 && sampled_.den()(0) != 0.0,
                "the discrete model needs a nonzero leading denominator coefficient a0");
}

bool PredictionModel::IsStable() const { return sampled_.IsStable(); }

Eigen::VectorXd PredictionModel::StepResponse(int n) const {
  PNEUMID_CHECK(n >= 1, "need at least one step coefficient, got n = {}", n);
  const Eigen::VectorXd& b = sampled_.num();
  const Eigen::VectorXd& a = sampled_.den();
  const int d = sampled_.DelaySamples();
  // a0 y[k] = sum_i b_i u[k-d-i] - sum_{i>=1} a_i y[k-i], u[k] = 1 for k >= 0.
  Eigen::VectorXd s = Eigen::VectorXd::Zero(n + 1);
  for (int k = 0; k <= n; ++k) {
    double acc = 0.0;
    for (int i = 0; i < b.size(); ++i) acc += (k - d - i >= 0) ? b(i) : 0.0;
    for (int i = 1; i < a.size() && i <= k; ++i) acc -= a(i) * s(k - i);
    s(k) = acc / a(0);
  }
  return s;
}

int PredictionModel::SettlingHorizon(double tol, int max_n) const {
  PNEUMID_CHECK(tol > 0.0, "tolerance must be positive, got {}", tol);
  PNEUMID_CHECK(max_n >= 1, "max_n must be >= 1, got {}", max_n);
  PNEUMID_CHECK(IsStable(),
                "DMC needs a stable model (a finite step response); the model {} is not stable",
                model_.ToString());
  const double s_inf = sampled_.DcGain();
  PNEUMID_CHECK(std::isfinite(s_inf) && s_inf != 0.0,
                "DMC needs a finite, nonzero static gain; got {}", s_inf);
  const Eigen::VectorXd s = StepResponse(max_n);
  int last_out = -1;
  for (int i = 0; i <= max_n; ++i) {
    if (std::abs(s(i) - s_inf) > tol * std::abs(s_inf)) last_out = i;
  }
  return std::min(max_n, last_out + 1);
}

Eigen::MatrixXd PredictionModel::DynamicMatrix(int P, int M) const {
  PNEUMID_CHECK(P >= 1 && M >= 1 && M <= P, "need 1 <= M <= P, got P = {}, M = {}", P, M);
  return pneumid::DynamicMatrix(StepResponse(P), P, M);
}

Eigen::MatrixXd DynamicMatrix(const Eigen::VectorXd& step, int P, int M) {
  PNEUMID_CHECK(P >= 1 && M >= 1 && M <= P, "need 1 <= M <= P, got P = {}, M = {}", P, M);
  PNEUMID_CHECK(step.size() >= 1, "the step response is empty");
  const Eigen::Index last = step.size() - 1;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(P, M);
  for (int i = 0; i < P; ++i) {
    for (int j = 0; j <= std::min(i, M - 1); ++j) {
      A(i, j) = step(std::min<Eigen::Index>(i + 1 - j, last));
    }
  }
  return A;
}

}  // namespace pneumid
