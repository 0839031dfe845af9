#include "pneumid/identify/evaluation/initial_state.hpp"

#include <cmath>

#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/transfer_function.hpp"
#include "../tall_skinny_qr.hpp"

namespace pneumid {

namespace {

int CheckAndDelay(const StateSpace& sys, const Eigen::MatrixXd& u) {
  PNEUMID_CHECK(sys.IsDiscrete(), "the initial state needs a discrete model, got Ts = {}",
                sys.Ts());
  PNEUMID_CHECK(u.cols() == sys.num_inputs(), "the input has {} columns, the model {} inputs",
                u.cols(), sys.num_inputs());
  PNEUMID_CHECK(u.rows() > 0, "no samples");
  PNEUMID_CHECK(u.allFinite(), "the input contains a non-finite value");
  return DelayInSamples(sys.delay(), sys.Ts());
}

}  // namespace

Eigen::MatrixXd SimulateFromState(const StateSpace& sys, const Eigen::MatrixXd& u,
                                  const Eigen::VectorXd& x0) {
  const int d = CheckAndDelay(sys, u);
  PNEUMID_CHECK(x0.size() == sys.num_states(), "x0 has {} entries, the model {} states", x0.size(),
                sys.num_states());
  const Eigen::Index N = u.rows();
  Eigen::MatrixXd y(N, sys.num_outputs());
  Eigen::VectorXd x = x0;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(sys.num_inputs());
  for (Eigen::Index t = 0; t < N; ++t) {
    const Eigen::VectorXd ut = t >= d ? Eigen::VectorXd(u.row(t - d).transpose()) : zero;
    y.row(t) = (sys.C() * x + sys.D() * ut).transpose();
    x = sys.A() * x + sys.B() * ut;
  }
  return y;
}

Eigen::VectorXd EstimateInitialState(const StateSpace& sys, const Eigen::MatrixXd& u,
                                     const Eigen::MatrixXd& y) {
  CheckAndDelay(sys, u);
  PNEUMID_CHECK(y.rows() == u.rows(), "output and input lengths differ: {} vs {}", y.rows(),
                u.rows());
  PNEUMID_CHECK(y.cols() == sys.num_outputs(), "the output has {} columns, the model {} outputs",
                y.cols(), sys.num_outputs());
  PNEUMID_CHECK(y.allFinite(), "the output contains a non-finite value");
  const int nx = sys.num_states();
  if (nx == 0) return Eigen::VectorXd();
  const int ny = sys.num_outputs();
  const Eigen::MatrixXd e = y - SimulateFromState(sys, u, Eigen::VectorXd::Zero(nx));
  // Rows [C A^t | e(t)'] per output, C A^t propagated; once it has decayed
  // below rounding of the first rows nothing more is learnt about x0.
  internal::TallSkinnyQr qr(nx + 1);
  const Eigen::Index kChunk = 1024;
  Eigen::MatrixXd block(kChunk, nx + 1);
  Eigen::MatrixXd cat = sys.C();  // C A^t, ny x nx
  const double scale0 = cat.norm();
  Eigen::Index filled = 0;
  for (Eigen::Index t = 0; t < y.rows(); ++t) {
    for (int i = 0; i < ny; ++i) {
      block.row(filled).head(nx) = cat.row(i);
      block(filled, nx) = e(t, i);
      if (++filled == kChunk) {
        qr.AddRows(block);
        filled = 0;
      }
    }
    cat = cat * sys.A();
    if (!cat.allFinite()) break;  // unstable model: later rows would overflow
    if (cat.norm() <= 1e-17 * scale0) break;
  }
  if (filled > 0) qr.AddRows(block.topRows(filled));
  const Eigen::MatrixXd R = qr.R();
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(R.topLeftCorner(nx, nx));
  return cod.solve(R.col(nx).head(nx));
}

}  // namespace pneumid
