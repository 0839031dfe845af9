#include "pneumid/identify/parametric/pem.hpp"

#include <cmath>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Dense>

#include "../ceres_logging.hpp"
#include "../parametric_filter.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/identify/parametric/iv.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

namespace {
constexpr EnumName<PolynomialStructure> kPolynomialStructureNames[] = {
    {PolynomialStructure::kArx, "arx"},
    {PolynomialStructure::kArmax, "armax"},
    {PolynomialStructure::kOe, "oe"},
    {PolynomialStructure::kBj, "bj"},
};
}  // namespace

std::string ToString(PolynomialStructure v) {
  return std::string(EnumToString(kPolynomialStructureNames, v));
}

PolynomialStructure PolynomialStructureFromString(const std::string& name) {
  return EnumFromString(kPolynomialStructureNames, name, "model structure");
}

bool PemOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (max_iterations < 0)
    return fail(fmt::format("max_iterations must be >= 0, got {}", max_iterations));
  if (!(function_tolerance > 0))
    return fail(fmt::format("function_tolerance must be > 0, got {}", function_tolerance));
  if (!(gradient_tolerance > 0))
    return fail(fmt::format("gradient_tolerance must be > 0, got {}", gradient_tolerance));
  if (!(parameter_tolerance > 0))
    return fail(fmt::format("parameter_tolerance must be > 0, got {}", parameter_tolerance));
  if (initial_arx_order < 0)
    return fail(fmt::format("initial_arx_order must be >= 0, got {}", initial_arx_order));
  return true;
}

namespace {

// True when all roots of the monic polynomial p (given as scalars) are strictly
// inside the unit circle.
bool IsStablePoly(const std::vector<double>& p) {
  if (p.size() <= 1) return true;
  Eigen::VectorXd v =
      Eigen::Map<const Eigen::VectorXd>(p.data(), static_cast<Eigen::Index>(p.size()));
  const Eigen::VectorXcd r = poly::Roots(v);
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (std::abs(r[i]) >= 1.0) return false;
  return true;
}

struct Layout {
  int na, nb, nk, nc, nd, nf;
  int size() const { return na + nb + nc + nd + nf; }
};

Layout LayoutOf(const PolynomialModel& m) {
  return {m.na(), m.nb(0), m.nk[0], m.nc(), m.nd(), m.nf(0)};
}

// Prediction errors of the general polynomial model
//   e(t) = D(q)/C(q) [A(q) y(t) - B(q)/F(q) u(t)]
// with zero initial conditions, and their analytic gradient, obtained by
// filtering the data once per polynomial ([1] Ljung, System Identification,
// 2nd ed., 1999, sec. 10.3, eqs. 10.54-10.56):
//   de/da_i =  D/C         y(t - i)
//   de/db_j = -D/(C F)     u(t - nk - j)
//   de/dc_i = -1/C         e(t - i)
//   de/dd_i =  1/C         v(t - i),  v = A y - w
//   de/df_i =  D/(C F)     w(t - i),  w = B/F u
// Each column is a delayed copy of one of five filtered signals, so an
// evaluation costs a few O(N) recursions instead of a forward-mode pass per
// parameter; the values equal those of automatic differentiation of the
// recursion (zero initial conditions commute with the delays).
class PredictionErrorCost final : public ceres::CostFunction {
 public:
  PredictionErrorCost(const Eigen::VectorXd& y, const Eigen::VectorXd& u, Layout l)
      : y_(y), u_(u), l_(l) {
    set_num_residuals(static_cast<int>(y.size()));
    mutable_parameter_block_sizes()->push_back(l.size());
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* p = parameters[0];
    Eigen::VectorXd A = Eigen::VectorXd::Zero(l_.na + 1), B = Eigen::VectorXd::Zero(l_.nk + l_.nb),
                    C = Eigen::VectorXd::Zero(l_.nc + 1), D = Eigen::VectorXd::Zero(l_.nd + 1),
                    F = Eigen::VectorXd::Zero(l_.nf + 1);
    A[0] = C[0] = D[0] = F[0] = 1.0;
    int k = 0;
    for (int i = 1; i <= l_.na; ++i) A[i] = p[k++];
    for (int i = 0; i < l_.nb; ++i) B[l_.nk + i] = p[k++];
    for (int i = 1; i <= l_.nc; ++i) C[i] = p[k++];
    for (int i = 1; i <= l_.nd; ++i) D[i] = p[k++];
    for (int i = 1; i <= l_.nf; ++i) F[i] = p[k++];
    if (!A.allFinite() || !B.allFinite() || !C.allFinite() || !D.allFinite() || !F.allFinite())
      return false;
    if (!IsStablePoly(std::vector<double>(C.data(), C.data() + C.size())) ||
        !IsStablePoly(std::vector<double>(F.data(), F.data() + F.size())))
      return false;
    const Eigen::Index n = y_.size();
    const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
    const Eigen::VectorXd w = internal::Filter(B, F, u_);
    const Eigen::VectorXd v = (l_.na > 0 ? internal::Filter(A, one, y_) : y_) - w;
    const Eigen::VectorXd e = internal::Filter(D, C, v);
    if (!e.allFinite()) return false;
    Eigen::Map<Eigen::VectorXd>(residuals, n) = e;
    if (jacobians == nullptr || jacobians[0] == nullptr) return true;
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    Eigen::Map<RowMajor> J(jacobians[0], n, l_.size());
    // Column `col` = sign * s(t - delay), zero for t < delay.
    auto delayed = [&](int col, const Eigen::VectorXd& s, int delay, double sign) {
      const Eigen::Index d = std::min<Eigen::Index>(delay, n);
      J.col(col).head(d).setZero();
      J.col(col).tail(n - d) = sign * s.head(n - d);
    };
    const Eigen::VectorXd CF = internal::Convolve(C, F);
    int col = 0;
    if (l_.na > 0) {
      const Eigen::VectorXd ya = internal::Filter(D, C, y_);
      for (int i = 1; i <= l_.na; ++i) delayed(col++, ya, i, 1.0);
    }
    const Eigen::VectorXd ub = internal::Filter(D, CF, u_);
    for (int j = 0; j < l_.nb; ++j) delayed(col++, ub, l_.nk + j, -1.0);
    if (l_.nc > 0) {
      const Eigen::VectorXd ec = internal::Filter(one, C, e);
      for (int i = 1; i <= l_.nc; ++i) delayed(col++, ec, i, -1.0);
    }
    if (l_.nd > 0) {
      const Eigen::VectorXd vc = internal::Filter(one, C, v);
      for (int i = 1; i <= l_.nd; ++i) delayed(col++, vc, i, 1.0);
    }
    if (l_.nf > 0) {
      const Eigen::VectorXd wf = internal::Filter(D, CF, w);
      for (int i = 1; i <= l_.nf; ++i) delayed(col++, wf, i, 1.0);
    }
    return J.allFinite();
  }

 private:
  const Eigen::VectorXd& y_;
  const Eigen::VectorXd& u_;
  Layout l_;
};

PolynomialModel FromParameters(const PolynomialModel& like, const Eigen::VectorXd& p) {
  PolynomialModel m = like;
  const Layout l = LayoutOf(like);
  int k = 0;
  for (int i = 1; i <= l.na; ++i) m.a[i] = p[k++];
  for (int i = 0; i < l.nb; ++i) m.b[0][l.nk + i] = p[k++];
  for (int i = 1; i <= l.nc; ++i) m.c[i] = p[k++];
  for (int i = 1; i <= l.nd; ++i) m.d[i] = p[k++];
  for (int i = 1; i <= l.nf; ++i) m.f[0][i] = p[k++];
  return m;
}

void Stabilize(PolynomialModel* m) {
  m->c = ReflectUnstableRoots(m->c);
  for (auto& f : m->f) f = ReflectUnstableRoots(f);
}

Termination FromCeres(ceres::TerminationType t) {
  switch (t) {
    case ceres::CONVERGENCE:
      return Termination::kConvergence;
    case ceres::NO_CONVERGENCE:
      return Termination::kNoConvergence;
    default:
      return Termination::kFailure;
  }
}

void CheckSignals(const Eigen::VectorXd& y, const Eigen::VectorXd& u) {
  PNEUMID_CHECK(y.size() == u.size(), "output and input lengths differ: {} vs {}", y.size(),
                u.size());
  PNEUMID_CHECK(y.allFinite() && u.allFinite(), "the data contain a non-finite value");
}

// Hannan-Rissanen: least squares of v(t) = -sum a_i v(t-i) + sum b_j u(t-nk-j)
// + sum c_i e1(t-i) + e1(t), with e1 the residuals of a high-order ARX fit.
// Returns [a; b; c] (na + nb + nc).
Eigen::VectorXd HannanRissanen(const Eigen::VectorXd& v, const Eigen::VectorXd& u, int na, int nb,
                               int nk, int nc, int high_order) {
  const Eigen::Index n = v.size();
  ArxOptions ho;
  ho.na = high_order;
  ho.nb = {high_order};
  ho.nk = {nk};
  const Eigen::MatrixXd um = u;
  const ArxResult hr = EstimateArx(v, um, 1.0, ho);
  Eigen::VectorXd e1 = PredictionErrors(hr.model, v, um);
  const Eigen::Index skip = ho.FirstRow();
  e1.head(skip).setZero();
  const int d = na + nb + nc;
  const Eigen::Index n0 = std::max<Eigen::Index>({skip + nc, na, nk + nb - 1});
  const Eigen::Index rows = n - n0;
  Eigen::MatrixXd phi(rows, d);
  for (int l = 1; l <= na; ++l) phi.col(l - 1) = -v.segment(n0 - l, rows);
  for (int j = 0; j < nb; ++j) phi.col(na + j) = u.segment(n0 - nk - j, rows);
  for (int l = 1; l <= nc; ++l) phi.col(na + nb + l - 1) = e1.segment(n0 - l, rows);
  const Eigen::VectorXd target = v.tail(rows) - e1.tail(rows);
  return phi.colPivHouseholderQr().solve(target);
}

int HighOrder(const PemOptions& o, int sum_orders, Eigen::Index n) {
  int h = o.initial_arx_order > 0 ? o.initial_arx_order : std::max(20, 2 * sum_orders);
  return static_cast<int>(std::min<Eigen::Index>(h, std::max<Eigen::Index>(1, n / 20)));
}

}  // namespace

PemResult RefinePem(const PolynomialModel& initial, const Eigen::VectorXd& y,
                    const Eigen::VectorXd& u, const PemOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid PEM options: {}", error);
  initial.Validate();
  PNEUMID_CHECK(initial.num_inputs() == 1, "prediction-error refinement handles one input, got {}",
                initial.num_inputs());
  CheckSignals(y, u);
  PolynomialModel start = initial;
  if (start.f.empty()) start.f = {Eigen::VectorXd::Ones(1)};
  Stabilize(&start);
  const Layout l = LayoutOf(start);
  PemResult result;
  EstimationSummary& s = result.summary;
  s.num_parameters = l.size();
  s.num_rows = y.size();
  if (y.size() <= 2 * l.size()) {
    result.model = start;
    s.termination = Termination::kFailure;
    s.message = fmt::format("{} samples are too few for {} parameters", y.size(), l.size());
    return result;
  }
  Eigen::VectorXd theta = start.Parameters();
  auto* cost = new PredictionErrorCost(y, u, l);
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, theta.data());
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // J^T J: O(N np^2) once, N >> np
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = options.function_tolerance;
  so.gradient_tolerance = options.gradient_tolerance;
  so.parameter_tolerance = options.parameter_tolerance;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary cs;
  internal::SilenceCeresLogging();
  ceres::Solve(so, &problem, &cs);
  const double N = static_cast<double>(y.size());
  s.iterations = static_cast<int>(cs.iterations.size()) - 1;
  s.initial_loss = 2.0 * cs.initial_cost / N;
  s.loss = 2.0 * cs.final_cost / N;
  s.termination = FromCeres(cs.termination_type);
  s.message = "Levenberg-Marquardt (Ceres): " + cs.message;
  result.model = FromParameters(start, theta);
  if (result.model.nf(0) == 0) result.model.f.clear();
  const double lambda = 2.0 * cs.final_cost / (N - l.size());
  result.model.noise_variance = lambda;
  // Covariance from the Jacobian at the optimum.
  double cost_value = 0.0;
  ceres::CRSMatrix jac;
  if (problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost_value, nullptr, nullptr, &jac)) {
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(jac.num_rows, jac.num_cols);
    for (int r = 0; r < jac.num_rows; ++r)
      for (int k = jac.rows[r]; k < jac.rows[r + 1]; ++k) J(r, jac.cols[k]) = jac.values[k];
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(J);
    const Eigen::MatrixXd R = qr.matrixQR().topRows(l.size()).triangularView<Eigen::Upper>();
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(R);
    const auto sv = svd.singularValues();
    s.condition_number = sv[sv.size() - 1] > 0 ? sv[0] / sv[sv.size() - 1] : INFINITY;
    if (sv[sv.size() - 1] > 1e-13 * sv[0]) {
      const Eigen::MatrixXd Rinv =
          R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(l.size(), l.size()));
      result.model.covariance = lambda * Rinv * Rinv.transpose();
    } else {
      s.warnings.push_back(
          "the Jacobian is singular at the optimum: orders too high (pole-zero "
          "cancellation) or poor excitation; no covariance");
    }
  }
  if (s.termination == Termination::kNoConvergence)
    s.warnings.push_back(fmt::format("not converged after {} iterations", options.max_iterations));
  return result;
}

PemResult EstimatePolynomial(PolynomialStructure structure, const PemOrders& o,
                             const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                             const PemOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid PEM options: {}", error);
  PNEUMID_CHECK(Ts > 0.0, "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(o.nb >= 1 && o.nk >= 0, "orders need nb >= 1 and nk >= 0, got nb = {}, nk = {}",
                o.nb, o.nk);
  CheckSignals(y, u);
  const bool uses_a =
      structure == PolynomialStructure::kArx || structure == PolynomialStructure::kArmax;
  const bool uses_c =
      structure == PolynomialStructure::kArmax || structure == PolynomialStructure::kBj;
  const bool uses_f =
      structure == PolynomialStructure::kOe || structure == PolynomialStructure::kBj;
  if (uses_a) PNEUMID_CHECK(o.na >= 0, "na must be >= 0, got {}", o.na);
  if (uses_c) PNEUMID_CHECK(o.nc >= 0, "nc must be >= 0, got {}", o.nc);
  if (structure == PolynomialStructure::kBj)
    PNEUMID_CHECK(o.nd >= 0, "nd must be >= 0, got {}", o.nd);
  if (uses_f) PNEUMID_CHECK(o.nf >= 0, "nf must be >= 0, got {}", o.nf);
  const Eigen::MatrixXd um = u;
  if (structure == PolynomialStructure::kArx) {
    ArxOptions ao;
    ao.na = o.na;
    ao.nb = {o.nb};
    ao.nk = {o.nk};
    const ArxResult r = EstimateArx(y, um, Ts, ao);
    return {r.model, r.summary};
  }
  PolynomialModel init;
  init.Ts = Ts;
  init.nk = {o.nk};
  std::vector<std::string> init_notes;
  if (structure == PolynomialStructure::kArmax) {
    const int high = HighOrder(options, o.na + o.nb + o.nc, y.size());
    const Eigen::VectorXd th = HannanRissanen(y, u, o.na, o.nb, o.nk, o.nc, high);
    init.structure = "ARMAX";
    init.a = Eigen::VectorXd::Ones(o.na + 1);
    init.a.tail(o.na) = th.head(o.na);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(o.nk + o.nb);
    b.tail(o.nb) = th.segment(o.na, o.nb);
    init.b = {b};
    init.c = Eigen::VectorXd::Ones(o.nc + 1);
    init.c.tail(o.nc) = th.tail(o.nc);
  } else {
    IvOptions io;
    io.na = o.nf;
    io.nb = o.nb;
    io.nk = o.nk;
    const IvResult iv = EstimateIv4(y, u, Ts, io);
    PolynomialModel base;
    if (iv.summary.IsSolutionUsable()) {
      base = iv.model;
    } else {
      ArxOptions ao;
      ao.na = o.nf;
      ao.nb = {o.nb};
      ao.nk = {o.nk};
      base = EstimateArx(y, um, Ts, ao).model;
      init_notes.push_back("IV4 initialisation failed, started from ARX: " + iv.summary.message);
    }
    init.structure = "OE";
    init.b = base.b;
    init.f = {ReflectUnstableRoots(base.a)};
    if (structure == PolynomialStructure::kBj) {
      init.structure = "BJ";
      // Refine B, F as output error first, then fit C, D to its residuals.
      const PemResult oe = RefinePem(init, y, u, options);
      init = oe.model;
      init.structure = "BJ";
      if (init.f.empty()) init.f = {Eigen::VectorXd::Ones(1)};
      const Eigen::VectorXd v = y - Simulate(init, um);
      const int high = HighOrder(options, o.nc + o.nd, y.size());
      Eigen::VectorXd th;
      {
        // ARMA(nd, nc) of v by Hannan-Rissanen (no input).
        ArxOptions ho;
        ho.na = high;
        ho.nb = {0};
        ho.nk = {0};
        const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(v.size(), 1);
        const ArxResult hr = EstimateArx(v, zero, 1.0, ho);
        Eigen::VectorXd e1 = PredictionErrors(hr.model, v, zero);
        e1.head(high).setZero();
        const Eigen::Index n0 = high + std::max(o.nc, o.nd);
        const Eigen::Index rows = v.size() - n0;
        Eigen::MatrixXd phi(rows, o.nd + o.nc);
        for (int l = 1; l <= o.nd; ++l) phi.col(l - 1) = -v.segment(n0 - l, rows);
        for (int l = 1; l <= o.nc; ++l) phi.col(o.nd + l - 1) = e1.segment(n0 - l, rows);
        th = phi.cols() > 0
                 ? Eigen::VectorXd(phi.colPivHouseholderQr().solve(v.tail(rows) - e1.tail(rows)))
                 : Eigen::VectorXd();
      }
      init.d = Eigen::VectorXd::Ones(o.nd + 1);
      init.d.tail(o.nd) = th.head(o.nd);
      init.d = ReflectUnstableRoots(init.d);
      init.c = Eigen::VectorXd::Ones(o.nc + 1);
      init.c.tail(o.nc) = th.tail(o.nc);
    }
  }
  PemResult r = RefinePem(init, y, u, options);
  r.model.structure = init.structure;
  for (auto& n : init_notes) r.summary.warnings.push_back(n);
  return r;
}

PemResult EstimatePolynomial(PolynomialStructure structure, const PemOrders& orders,
                             const Dataset& data, const PemOptions& options, int input,
                             int output) {
  data.RequireUniform();
  data.RequireSamples(
      4 * (orders.na + orders.nb + orders.nc + orders.nd + orders.nf) + orders.nk + 2,
      ToString(structure));
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(), "input column {} out of range [0, {})",
                input, data.num_inputs());
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(), "output column {} out of range [0, {})",
                output, data.num_outputs());
  return EstimatePolynomial(structure, orders, data.y(output), data.u(input), data.SampleTime(),
                            options);
}

}  // namespace pneumid
