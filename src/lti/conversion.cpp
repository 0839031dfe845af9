#include "pneumid/lti/conversion.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <unsupported/Eigen/MatrixFunctions>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXcd;
using Eigen::VectorXd;

// Splits a continuous delay into whole samples and a fractional remainder in
// [0, Ts). A ratio within a relative 1e-9 of an integer counts as an integer.
void SplitDelay(double delay, double Ts, int* whole, double* fraction) {
  DelayInSamples(delay, Ts);  // throws for a count an int cannot hold
  const double r = delay / Ts;
  const double n = std::round(r);
  if (std::abs(r - n) <= 1e-9 * std::max(1.0, r)) {
    *whole = static_cast<int>(n);
    *fraction = 0.0;
    return;
  }
  *whole = static_cast<int>(std::floor(r));
  *fraction = delay - *whole * Ts;
}

// Characteristic polynomial det(sI - M), descending powers, from the eigenvalues.
VectorXd CharPoly(const MatrixXd& M) {
  if (M.rows() == 0) return VectorXd::Ones(1);
  Eigen::EigenSolver<MatrixXd> es(M, false);
  return poly::FromRoots(es.eigenvalues());
}

// expm([A B; 0 0] t) -> Phi(t) = exp(A t), Gamma(t) = int_0^t exp(A s) ds B.
void ZohBlocks(const MatrixXd& A, const MatrixXd& B, double t, MatrixXd* Phi, MatrixXd* Gamma) {
  const Eigen::Index n = A.rows(), m = B.cols();
  MatrixXd M = MatrixXd::Zero(n + m, n + m);
  M.topLeftCorner(n, n) = A * t;
  M.topRightCorner(n, m) = B * t;
  const MatrixXd E = M.exp();
  *Phi = E.topLeftCorner(n, n);
  *Gamma = E.topRightCorner(n, m);
}

void CheckMethodArguments(const char* what, double Ts, DiscretizationMethod method,
                          double prewarp) {
  PNEUMID_CHECK(std::isfinite(Ts) && Ts > 0.0, "{}: sample time must be > 0, got Ts = {}", what,
                Ts);
  PNEUMID_CHECK(std::isfinite(prewarp) && prewarp >= 0.0,
                "{}: prewarp frequency must be >= 0 rad/s (0 = none), got {}", what, prewarp);
  PNEUMID_CHECK(prewarp == 0.0 || method == DiscretizationMethod::kTustin,
                "{}: a prewarp frequency applies to the tustin method only, got method {} with "
                "prewarp = {} rad/s",
                what, ToString(method), prewarp);
  PNEUMID_CHECK(prewarp * Ts / 2.0 < M_PI / 2.0,
                "{}: prewarp frequency must be below the Nyquist frequency pi/Ts = {} rad/s, "
                "got {} rad/s",
                what, M_PI / Ts, prewarp);
}

// The sample period seen by the bilinear substitution: Ts, or with prewarping
// at w, 2 tan(w Ts / 2) / w, so that s = w / tan(w Ts/2) (z-1)/(z+1).
double BilinearPeriod(double Ts, double prewarp) {
  if (prewarp == 0.0) return Ts;
  return 2.0 * std::tan(prewarp * Ts / 2.0) / prewarp;
}

// Generalized bilinear transform, s = (z - 1) / (T (alpha z + 1 - alpha)):
// alpha = 0 forward Euler, 1/2 Tustin, 1 backward difference.
StateSpace Gbt(const StateSpace& g, double T, double alpha, double Ts_out, double delay_out) {
  const Eigen::Index n = g.num_states();
  const MatrixXd I = MatrixXd::Identity(n, n);
  const MatrixXd ima = I - alpha * T * g.A();
  Eigen::FullPivLU<MatrixXd> lu(ima);
  PNEUMID_CHECK(n == 0 || lu.isInvertible(),
                "c2d: I - {} Ts A is singular (a pole at s = {}), the substitution has no "
                "discrete equivalent",
                alpha, 1.0 / (alpha * T));
  const MatrixXd Ad = lu.solve(I + (1.0 - alpha) * T * g.A());
  const MatrixXd Bd = lu.solve(T * g.B());
  const MatrixXd Cd = g.C() * lu.inverse();
  const MatrixXd Dd = g.D() + alpha * g.C() * Bd;
  return StateSpace(Ad, Bd, Cd, Dd, Ts_out, delay_out);
}

bool IsOrigin(std::complex<double> r, double scale) { return std::abs(r) <= 1e-12 * scale; }

TransferFunction C2DMatched(const TransferFunction& g, double Ts) {
  const VectorXd num = poly::TrimLeading(g.num());
  const VectorXd den = poly::TrimLeading(g.den());
  const VectorXcd zeros = g.Zeros();
  const VectorXcd poles = g.Poles();
  double scale = 1.0;
  for (Eigen::Index i = 0; i < zeros.size(); ++i) scale = std::max(scale, std::abs(zeros[i]));
  for (Eigen::Index i = 0; i < poles.size(); ++i) scale = std::max(scale, std::abs(poles[i]));
  // Gain of s^(kp - kz) G(s) at s = 0, with kp (kz) poles (zeros) at the origin.
  std::complex<double> gc = num[0] / den[0];
  std::complex<double> gd = 1.0;
  int excess = 0;
  VectorXcd zz(zeros.size()), zp(poles.size());
  for (Eigen::Index i = 0; i < zeros.size(); ++i) {
    zz[i] = std::exp(zeros[i] * Ts);
    if (IsOrigin(zeros[i], scale)) {
      --excess;
    } else {
      gc *= -zeros[i];
      gd *= 1.0 - zz[i];
    }
  }
  for (Eigen::Index i = 0; i < poles.size(); ++i) {
    zp[i] = std::exp(poles[i] * Ts);
    if (IsOrigin(poles[i], scale)) {
      ++excess;
    } else {
      gc /= -poles[i];
      gd /= 1.0 - zp[i];
    }
  }
  // Match s^e G(s) at s = 0 with ((z - 1)/Ts)^e Gd(z) at z = 1.
  const double k = (gc / gd).real() * std::pow(Ts, excess);
  const VectorXd nz = k * poly::FromRoots(zz);
  const VectorXd dz = poly::FromRoots(zp);
  VectorXd nfull = VectorXd::Zero(dz.size());
  nfull.tail(nz.size()) = nz;
  const int d = DelayInSamples(g.delay(), Ts);
  return TransferFunction(nfull, dz, Ts, d * Ts);
}

}  // namespace

namespace {
constexpr EnumName<DiscretizationMethod> kDiscretizationMethodNames[] = {
    {DiscretizationMethod::kZoh, "zoh"},
    {DiscretizationMethod::kFoh, "foh"},
    {DiscretizationMethod::kTustin, "tustin"},
    {DiscretizationMethod::kEuler, "euler"},
    {DiscretizationMethod::kBackwardDiff, "backward_diff"},
    {DiscretizationMethod::kMatched, "matched"},
    {DiscretizationMethod::kTustin, "bilinear"},
    {DiscretizationMethod::kEuler, "forward_diff"},
};
}  // namespace

std::string ToString(DiscretizationMethod v) {
  return std::string(EnumToString(kDiscretizationMethodNames, v));
}

DiscretizationMethod DiscretizationMethodFromString(const std::string& name) {
  return EnumFromString(kDiscretizationMethodNames, name, "discretization method");
}

StateSpace ToStateSpace(const TransferFunction& tf) {
  VectorXd den, num;
  if (tf.IsDiscrete()) {
    den = tf.den();
    num = tf.num();
  } else {
    den = poly::TrimLeading(tf.den());
    const VectorXd nt = poly::TrimLeading(tf.num());
    num = VectorXd::Zero(den.size());
    num.tail(nt.size()) = nt;
  }
  const Eigen::Index n = den.size() - 1;
  const double a0 = den[0];
  const VectorXd a = den / a0;
  const VectorXd b = num / a0;
  MatrixXd A = MatrixXd::Zero(n, n), B = MatrixXd::Zero(n, 1), C(1, n), D(1, 1);
  for (Eigen::Index j = 0; j < n; ++j) {
    A(0, j) = -a[j + 1];
    C(0, j) = b[j + 1] - b[0] * a[j + 1];
  }
  for (Eigen::Index i = 1; i < n; ++i) A(i, i - 1) = 1.0;
  if (n > 0) B(0, 0) = 1.0;
  D(0, 0) = b[0];
  return StateSpace(A, B, C, D, tf.Ts(), tf.delay());
}

TransferFunction ToTransferFunction(const StateSpace& ss, int input, int output) {
  PNEUMID_CHECK(input >= 0 && input < ss.num_inputs(),
                "ToTransferFunction: input index {} out of range [0, {})", input, ss.num_inputs());
  PNEUMID_CHECK(output >= 0 && output < ss.num_outputs(),
                "ToTransferFunction: output index {} out of range [0, {})", output,
                ss.num_outputs());
  const MatrixXd b = ss.B().col(input);
  const MatrixXd c = ss.C().row(output);
  const double d = ss.D()(output, input);
  // det(sI - A + b c) = det(sI - A) (1 + c (sI - A)^-1 b), so that
  // c (sI - A)^-1 b + d = (det(sI - A + b c) - det(sI - A) + d det(sI - A)) / det(sI - A).
  const VectorXd den = CharPoly(ss.A());
  const VectorXd num = CharPoly(ss.A() - b * c) - den + d * den;
  return TransferFunction(num, den, ss.Ts(), ss.delay());
}

StateSpace C2D(const StateSpace& g, double Ts, DiscretizationMethod method, double prewarp) {
  PNEUMID_CHECK(!g.IsDiscrete(), "c2d: the model is already discrete (Ts = {} s)", g.Ts());
  CheckMethodArguments("c2d", Ts, method, prewarp);
  const Eigen::Index n = g.num_states(), m = g.num_inputs(), p = g.num_outputs();
  int whole = 0;
  double fraction = 0.0;
  SplitDelay(g.delay(), Ts, &whole, &fraction);
  if (method != DiscretizationMethod::kZoh && fraction > 0.0) {
    // Other holds: the delay is rounded to the nearest whole sample.
    if (fraction >= 0.5 * Ts) ++whole;
    fraction = 0.0;
  }
  const double delay_out = whole * Ts;
  switch (method) {
    case DiscretizationMethod::kZoh: {
      if (fraction == 0.0) {
        MatrixXd Phi, Gamma;
        ZohBlocks(g.A(), g.B(), Ts, &Phi, &Gamma);
        return StateSpace(Phi, Gamma, g.C(), g.D(), Ts, delay_out);
      }
      // Modified z-transform: over [kT, kT + f) the input is u[k-1], over
      // [kT + f, (k+1)T) it is u[k]. With the extra state v[k] = u[k-1]:
      //   x[k+1] = Phi(T-f) Phi(f) x[k] + Phi(T-f) Gamma(f) v[k] + Gamma(T-f) u[k]
      //   v[k+1] = u[k],   y[k] = C x[k] + D v[k].
      MatrixXd Phi1, Gamma1, Phi2, Gamma2;
      ZohBlocks(g.A(), g.B(), fraction, &Phi1, &Gamma1);
      ZohBlocks(g.A(), g.B(), Ts - fraction, &Phi2, &Gamma2);
      MatrixXd Ad = MatrixXd::Zero(n + m, n + m), Bd = MatrixXd::Zero(n + m, m);
      MatrixXd Cd(p, n + m);
      Ad.topLeftCorner(n, n) = Phi2 * Phi1;
      Ad.topRightCorner(n, m) = Phi2 * Gamma1;
      Bd.topRows(n) = Gamma2;
      Bd.bottomRows(m) = MatrixXd::Identity(m, m);
      Cd.leftCols(n) = g.C();
      Cd.rightCols(m) = g.D();
      return StateSpace(Ad, Bd, Cd, MatrixXd::Zero(p, m), Ts, delay_out);
    }
    case DiscretizationMethod::kFoh: {
      // Triangle hold: expm([A B 0; 0 0 I; 0 0 0] Ts) = [Phi G1 G2; 0 I I; 0 0 I]
      //   Ad = Phi, Bd = G1 + (Phi - I) G2, Cd = C, Dd = D + C G2.
      MatrixXd M = MatrixXd::Zero(n + 2 * m, n + 2 * m);
      M.block(0, 0, n, n) = g.A() * Ts;
      M.block(0, n, n, m) = g.B() * Ts;
      M.block(n, n + m, m, m) = MatrixXd::Identity(m, m);
      const MatrixXd E = M.exp();
      const MatrixXd Phi = E.block(0, 0, n, n);
      const MatrixXd G1 = E.block(0, n, n, m);
      const MatrixXd G2 = E.block(0, n + m, n, m);
      const MatrixXd Bd = G1 - G2 + Phi * G2;
      return StateSpace(Phi, Bd, g.C(), g.D() + g.C() * G2, Ts, delay_out);
    }
    case DiscretizationMethod::kTustin:
      return Gbt(g, BilinearPeriod(Ts, prewarp), 0.5, Ts, delay_out);
    case DiscretizationMethod::kEuler:
      return Gbt(g, Ts, 0.0, Ts, delay_out);
    case DiscretizationMethod::kBackwardDiff:
      return Gbt(g, Ts, 1.0, Ts, delay_out);
    case DiscretizationMethod::kMatched: {
      PNEUMID_CHECK(m == 1 && p == 1,
                    "c2d: the matched method needs a SISO model, got {} inputs and {} outputs", m,
                    p);
      return ToStateSpace(C2DMatched(ToTransferFunction(g), Ts));
    }
  }
  return g;
}

TransferFunction C2D(const TransferFunction& g, double Ts, DiscretizationMethod method,
                     double prewarp) {
  PNEUMID_CHECK(!g.IsDiscrete(), "c2d: the model is already discrete (Ts = {} s)", g.Ts());
  CheckMethodArguments("c2d", Ts, method, prewarp);
  if (method == DiscretizationMethod::kMatched) return C2DMatched(g, Ts);
  return ToTransferFunction(C2D(ToStateSpace(g), Ts, method, prewarp));
}

StateSpace D2C(const StateSpace& g, DiscretizationMethod method, double prewarp) {
  PNEUMID_CHECK(g.IsDiscrete(), "d2c: the model is already continuous");
  PNEUMID_CHECK(method == DiscretizationMethod::kZoh || method == DiscretizationMethod::kTustin,
                "d2c: method {} is not invertible here; use zoh or tustin", ToString(method));
  const double Ts = g.Ts();
  CheckMethodArguments("d2c", Ts, method, prewarp);
  const Eigen::Index n = g.num_states(), m = g.num_inputs();
  const VectorXcd poles = g.Poles();
  if (method == DiscretizationMethod::kZoh) {
    for (Eigen::Index i = 0; i < poles.size(); ++i) {
      const std::complex<double> z = poles[i];
      const bool on_axis = std::abs(z.imag()) <= 1e-9 * std::max(1.0, std::abs(z));
      PNEUMID_CHECK(!(on_axis && z.real() <= 1e-12),
                    "d2c zoh: pole at z = {:.6g} lies on the closed negative real axis, where no "
                    "real matrix logarithm (no continuous zoh equivalent) exists",
                    z.real());
    }
    MatrixXd M = MatrixXd::Zero(n + m, n + m);
    M.topLeftCorner(n, n) = g.A();
    M.topRightCorner(n, m) = g.B();
    M.bottomRightCorner(m, m) = MatrixXd::Identity(m, m);
    const MatrixXd L = M.log() / Ts;
    return StateSpace(L.topLeftCorner(n, n), L.topRightCorner(n, m), g.C(), g.D(), 0.0, g.delay());
  }
  // Tustin: with T the (prewarped) period and P = (Ad + I)^-1,
  //   A = 2/T P (Ad - I),  B = 2/T P Bd,  C = 2 Cd P,  D = Dd - Cd P Bd.
  const double T = BilinearPeriod(Ts, prewarp);
  const MatrixXd I = MatrixXd::Identity(n, n);
  Eigen::FullPivLU<MatrixXd> lu(g.A() + I);
  PNEUMID_CHECK(n == 0 || lu.isInvertible(),
                "d2c tustin: a pole at z = -1 has no continuous bilinear equivalent");
  const MatrixXd A = (2.0 / T) * lu.solve(g.A() - I);
  const MatrixXd B = (2.0 / T) * lu.solve(g.B());
  const MatrixXd PT = lu.inverse();
  const MatrixXd C = 2.0 * g.C() * PT;
  const MatrixXd D = g.D() - g.C() * PT * g.B();
  return StateSpace(A, B, C, D, 0.0, g.delay());
}

TransferFunction D2C(const TransferFunction& g, DiscretizationMethod method, double prewarp) {
  PNEUMID_CHECK(g.IsDiscrete(), "d2c: the model is already continuous");
  // Leading zeros of B(z^-1) beyond the first are a pure delay: b = z^-k b'.
  // It is taken out as k Ts of continuous delay (exact for zoh).
  const VectorXd& num = g.num();
  Eigen::Index lead = 0;
  while (lead < num.size() && num[lead] == 0.0) ++lead;
  if (lead >= 2 && lead < num.size()) {
    const Eigen::Index k = lead - 1;
    VectorXd shifted = VectorXd::Zero(num.size());
    shifted.head(num.size() - k) = num.tail(num.size() - k);
    const TransferFunction inner(shifted, g.den(), g.Ts(), g.delay() + k * g.Ts());
    return D2C(inner, method, prewarp);
  }
  const TransferFunction c = ToTransferFunction(D2C(ToStateSpace(g), method, prewarp));
  return c;
}

}  // namespace pneumid
