#include "pneumid/identify/parametric/subspace.hpp"

#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "../tall_skinny_qr.hpp"

namespace pneumid {

namespace {
constexpr EnumName<SubspaceWeighting> kSubspaceWeightingNames[] = {
    {SubspaceWeighting::kMoesp, "moesp"},
    {SubspaceWeighting::kN4sid, "n4sid"},
    {SubspaceWeighting::kCva, "cva"},
};

// The weighted matrix M of the unifying theorem (subspace.hpp) and W1^(-1),
// from the LQ factor L of [U_f; U_p; Y_p; Y_f] with horizon s.
void WeightedProjection(const Eigen::MatrixXd& L, int s, SubspaceWeighting w, Eigen::MatrixXd* M,
                        Eigen::MatrixXd* w1_inverse) {
  const Eigen::MatrixXd L32 = L.block(3 * s, s, s, 2 * s);
  *w1_inverse = Eigen::MatrixXd::Identity(s, s);
  switch (w) {
    case SubspaceWeighting::kMoesp:
      *M = L32;
      return;
    case SubspaceWeighting::kN4sid: {
      // O = L32 L22^+ [L21 L22]: L22 is singular when the input is constant
      // over the whole record or most of it, hence the pseudo-inverse
      // (minimum-norm least squares of L22' X' = L32').
      const Eigen::MatrixXd L2 = L.block(s, 0, 2 * s, 3 * s);  // [L21 L22]
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(
          L.block(s, s, 2 * s, 2 * s).transpose());
      const Eigen::MatrixXd X = cod.solve(L32.transpose()).transpose();
      *M = X * L2;
      return;
    }
    case SubspaceWeighting::kCva: {
      const Eigen::MatrixXd L33 = L.block(3 * s, 3 * s, s, s);
      const Eigen::MatrixXd sigma = L32 * L32.transpose() + L33 * L33.transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(sigma);
      // Noise-free data make sigma singular: eigenvalues are floored.
      const Eigen::VectorXd lambda = eig.eigenvalues().cwiseMax(
          std::max(eig.eigenvalues().maxCoeff(), 0.0) * 1e-12 + std::numeric_limits<double>::min());
      const Eigen::MatrixXd& V = eig.eigenvectors();
      *w1_inverse = V * lambda.cwiseSqrt().asDiagonal() * V.transpose();
      *M = V * lambda.cwiseSqrt().cwiseInverse().asDiagonal() * V.transpose() * L32;
      return;
    }
  }
}
}  // namespace

std::string ToString(SubspaceWeighting w) {
  return std::string(EnumToString(kSubspaceWeightingNames, w));
}

SubspaceWeighting SubspaceWeightingFromString(const std::string& name) {
  return EnumFromString(kSubspaceWeightingNames, name, "subspace weighting", true);
}

bool SubspaceOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (order < 0) return fail(fmt::format("order must be >= 0 (0 = automatic), got {}", order));
  if (max_order < 1) return fail(fmt::format("max_order must be >= 1, got {}", max_order));
  if (horizon < 0)
    return fail(fmt::format("horizon must be >= 0 (0 = automatic), got {}", horizon));
  const int nmax = order > 0 ? order : max_order;
  if (horizon > 0 && horizon <= nmax)
    return fail(fmt::format("horizon {} must exceed the (maximum) order {}", horizon, nmax));
  return true;
}

SubspaceResult EstimateSubspace(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                                const SubspaceOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid subspace options: {}", error);
  PNEUMID_CHECK(Ts > 0, "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(y.size() == u.size(), "output and input lengths differ: {} vs {}", y.size(),
                u.size());
  PNEUMID_CHECK(y.allFinite() && u.allFinite(), "the data contain a non-finite value");
  const int nmax = o.order > 0 ? o.order : o.max_order;
  const int s = o.horizon > 0 ? o.horizon : std::max(2 * nmax, 10);
  const Eigen::Index N = y.size();
  const Eigen::Index j = N - 2 * s + 1;
  PNEUMID_CHECK(j >= 8 * s, "{} samples are too few for horizon {} (need at least {})", N, s,
                10 * s);
  // QR of the j x 4s matrix H' whose row t is [U_f U_p Y_p Y_f] at column t.
  internal::TallSkinnyQr qr(4 * s);
  const Eigen::Index kChunk = 1024;
  Eigen::MatrixXd rows(kChunk, 4 * s);
  for (Eigen::Index t0 = 0; t0 < j; t0 += kChunk) {
    const Eigen::Index m = std::min(kChunk, j - t0);
    for (int i = 0; i < s; ++i) {
      rows.col(i).head(m) = u.segment(t0 + s + i, m);
      rows.col(s + i).head(m) = u.segment(t0 + i, m);
      rows.col(2 * s + i).head(m) = y.segment(t0 + i, m);
      rows.col(3 * s + i).head(m) = y.segment(t0 + s + i, m);
    }
    qr.AddRows(rows.topRows(m));
  }
  const Eigen::MatrixXd L = qr.R().transpose();  // H = L Q'
  Eigen::MatrixXd M, w1_inverse;
  WeightedProjection(L, s, o.weighting, &M, &w1_inverse);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU);
  SubspaceResult r;
  r.singular_values = svd.singularValues();
  const Eigen::VectorXd& sv = r.singular_values;
  int n = o.order;
  if (n == 0) {
    double best_gap = -1;
    n = 1;
    for (int k = 1; k <= std::min<int>(o.max_order, static_cast<int>(sv.size()) - 1); ++k) {
      if (sv[k] <= 0) {
        n = k;
        break;
      }
      const double gap = std::log10(sv[k - 1]) - std::log10(sv[k]);
      if (gap > best_gap) {
        best_gap = gap;
        n = k;
      }
    }
  }
  r.order = n;
  const Eigen::MatrixXd gamma =
      w1_inverse * svd.matrixU().leftCols(n) * sv.head(n).cwiseSqrt().asDiagonal();
  const Eigen::MatrixXd C = gamma.topRows(1);
  const Eigen::MatrixXd A =
      gamma.topRows(s - 1).colPivHouseholderQr().solve(gamma.bottomRows(s - 1));
  // B, D, x0 by least squares: regressors [C A^t (n) | C X_t (n) | u(t)] with
  // X_{t+1} = A X_t + I u(t), X_0 = 0.
  const int nd = o.feedthrough ? 1 : 0;
  const int p = 2 * n + nd;
  internal::TallSkinnyQr qr2(p + 1);
  Eigen::MatrixXd block(kChunk, p + 1);
  Eigen::RowVectorXd cat = C;  // C A^t
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(n, n);
  Eigen::Index filled = 0;
  for (Eigen::Index t = 0; t < N; ++t) {
    block.row(filled).head(n) = cat;
    block.row(filled).segment(n, n) = C * X;
    if (nd) block(filled, 2 * n) = u[t];
    block(filled, p) = y[t];
    if (++filled == kChunk || t == N - 1) {
      qr2.AddRows(block.topRows(filled));
      filled = 0;
    }
    cat = cat * A;
    X = A * X;
    X.diagonal().array() += u[t];
  }
  const Eigen::MatrixXd R2 = qr2.R();
  const Eigen::MatrixXd R11 = R2.topLeftCorner(p, p);
  Eigen::VectorXd theta = R11.triangularView<Eigen::Upper>().solve(R2.col(p).head(p));
  const bool finite = A.allFinite() && C.allFinite() && theta.allFinite();
  if (!finite) theta.setZero();
  r.x0 = theta.head(n);
  const Eigen::MatrixXd B = theta.segment(n, n);
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(1, 1);
  if (nd) D(0, 0) = theta[2 * n];
  r.model = finite ? StateSpace(A, B, C, D, Ts)
                   : StateSpace(Eigen::MatrixXd::Zero(n, n), B, Eigen::MatrixXd::Zero(1, n), D, Ts);
  EstimationSummary& sum = r.summary;
  sum.num_rows = N;
  sum.num_parameters = n * n + 2 * n + nd;
  sum.loss = R2(p, p) * R2(p, p) / static_cast<double>(N);
  sum.termination = finite ? Termination::kConvergence : Termination::kFailure;
  static constexpr const char* kLabel[] = {"PO-MOESP", "N4SID", "CVA"};
  sum.message = fmt::format("{}, order {}, horizon {}{}", kLabel[static_cast<int>(o.weighting)], n,
                            s, finite ? "" : ": non-finite A, C or B, D, x0 (unstable A?)");
  if (!finite) return r;
  if (!r.model.IsStable()) sum.warnings.push_back("the identified model is unstable");
  return r;
}

SubspaceResult EstimateSubspace(const Dataset& data, const SubspaceOptions& options, int input,
                                int output) {
  data.RequireUniform();
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(), "input column {} out of range [0, {})",
                input, data.num_inputs());
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(), "output column {} out of range [0, {})",
                output, data.num_outputs());
  return EstimateSubspace(data.y(output), data.u(input), data.SampleTime(), options);
}

}  // namespace pneumid
