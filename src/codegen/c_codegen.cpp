#include "pneumid/codegen/c_codegen.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include <fmt/format.h>
#include <Eigen/Core>
#include <Eigen/LU>
#include <nlohmann/json.hpp>

#include "c_runtime.hpp"
#include "c_text.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/control/duty_modulator.hpp"
#include "pneumid/control/gpc.hpp"
#include "pneumid/control/inverse_map_controller.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/control/narx_linearizing_controller.hpp"
#include "pneumid/control/pid.hpp"

namespace pneumid {

namespace {

constexpr EnumName<CodegenPrecision> kPrecisionNames[] = {
    {CodegenPrecision::kDouble, "double"},
    {CodegenPrecision::kFloat, "float"},
};

constexpr double kInf = std::numeric_limits<double>::infinity();

// One member of a generated struct.
struct Field {
  enum Kind { kReal, kInt, kByte } kind;
  std::string name;
  int count;  // 0: a scalar
  std::string comment;
};

// Builds the text of one module: constants (counted as flash), struct
// members (counted as RAM), and the code, with "PFX_" for the prefix.
class Module {
 public:
  explicit Module(const CodegenOptions& options)
      : options_(options), is_float_(options.precision == CodegenPrecision::kFloat) {}

  std::size_t RealSize() const { return is_float_ ? 4 : 8; }
  bool is_float() const { return is_float_; }

  // A C literal of v in the module's precision ("PFX_INF" for infinities).
  std::string Literal(double v) const { return internal::CLiteral(v, is_float_); }

  // #define PFX_NAME literal (a scalar constant; macros cost no flash of their own).
  void Scalar(const std::string& name, double v, const std::string& comment) {
    constants_ += fmt::format("#define PFX_{} {} /* {} */\n", name, Literal(v), comment);
    macros_.insert(name);
  }

  // Names written PFX_NAME that are macros (upper-case prefix in the output).
  std::set<std::string> macros_ = {"ZERO",
                                   "ONE",
                                   "THOUSAND",
                                   "INF",
                                   "EPSILON",
                                   "FABS",
                                   "HYPOT",
                                   "ISFINITE",
                                   "TS",
                                   "STATE_BYTES",
                                   "QP_N",
                                   "QP_M",
                                   "QP_SOLVED",
                                   "QP_INFEASIBLE",
                                   "QP_MAX_ITERATIONS",
                                   "QP_MAX_ITERATIONS_REACHED",
                                   "QP_WARM_START",
                                   "QP_TOLERANCE",
                                   "Y_VALID_MIN",
                                   "Y_VALID_MAX",
                                   "SAFE_INPUT",
                                   "FAULT_NONE",
                                   "FAULT_MEASUREMENT_NOT_FINITE",
                                   "FAULT_MEASUREMENT_OUT_OF_RANGE",
                                   "FAULT_SETPOINT_NOT_FINITE",
                                   "FAULT_OUTPUT_NOT_FINITE"};

  // static const PFX_real PFX_name[n] (a matrix column-major); at least one entry.
  void Array(const std::string& name, const Eigen::Ref<const Eigen::MatrixXd>& m,
             const std::string& comment) {
    const Eigen::Index stored = std::max<Eigen::Index>(m.size(), 1);
    const std::string body = internal::CInitializer(m, is_float_);
    constants_ += fmt::format("/* {} */\nstatic const PFX_real PFX_{}[{}] = {{{}}};\n", comment,
                              name, stored, body);
    const_bytes_ += static_cast<std::size_t>(stored) * RealSize();
  }

  void Member(Field f) { state_.push_back(std::move(f)); }
  void QpMember(Field f) { qp_.push_back(std::move(f)); }

  // Struct text and size (reals, then ints, then bytes; padded to the
  // alignment of its widest member).
  std::string StructText(const std::vector<Field>& fields, const std::string& extra,
                         std::size_t extra_bytes, std::size_t* bytes) const {
    std::string text;
    std::size_t size = 0;
    auto put = [&](Field::Kind kind, const char* type, std::size_t unit) {
      for (const Field& f : fields) {
        if (f.kind != kind) continue;
        const int count = std::max(f.count, 1);
        text += f.count > 0 ? fmt::format("  {} {}[{}]; /* {} */\n", type, f.name, count, f.comment)
                            : fmt::format("  {} {}; /* {} */\n", type, f.name, f.comment);
        size += static_cast<std::size_t>(count) * unit;
      }
    };
    put(Field::kReal, "PFX_real", RealSize());
    text += extra;
    size += extra_bytes;
    put(Field::kInt, "int", 4);
    put(Field::kByte, "unsigned char", 1);
    const std::size_t align = std::max<std::size_t>(RealSize(), 4);
    *bytes = (size + align - 1) / align * align;
    return text;
  }

  const CodegenOptions& options() const { return options_; }
  std::string constants_;
  std::string code_;
  std::vector<Field> state_, qp_;
  std::size_t const_bytes_ = 0;
  // The QP's iteration cap in the module (the certificate's).
  int qp_max_iterations_ = 0;
  // Kernels the code calls.
  bool dot_ = false, dot_strided_ = false, gemv_col_ = false, qp_solver_ = false;

 private:
  CodegenOptions options_;
  bool is_float_ = false;
};

// Clip of InputLimits (controller.cpp): std::clamp to u_prev +- du_max, then
// to [u_min, u_max]; sides that are infinite are left out.
void EmitClip(Module& m, const InputLimits& lim) {
  // A non-finite u (the law overflowed) stays one: PFX_step counts the fault
  // and restarts the law instead of applying a limit.
  std::string body = "  if (!PFX_ISFINITE(u)) return u;\n";
  if (std::isfinite(lim.du_max)) {
    body += fmt::format(
        "  {{\n    const PFX_real lo = u_prev - {0}, hi = u_prev + {0};\n"
        "    u = u < lo ? lo : (hi < u ? hi : u);\n  }}\n",
        m.Literal(lim.du_max));
  } else {
    body += "  (void)u_prev;\n";
  }
  const bool lo = std::isfinite(lim.u_min), hi = std::isfinite(lim.u_max);
  if (lo && hi)
    body += fmt::format("  u = u < {0} ? {0} : ({1} < u ? {1} : u);\n", m.Literal(lim.u_min),
                        m.Literal(lim.u_max));
  else if (lo)
    body += fmt::format("  if (u < {0}) u = {0};\n", m.Literal(lim.u_min));
  else if (hi)
    body += fmt::format("  if ({0} < u) u = {0};\n", m.Literal(lim.u_max));
  m.code_ +=
      "/* u clipped to u_prev +- du_max, then to [u_min, u_max] (InputLimits::Clip); a\n"
      "   non-finite u is returned as it is (a fault). */\n"
      "static PFX_real PFX_clip(PFX_real u, PFX_real u_prev) {\n" +
      body + "  return u;\n}\n\n";
}

// The QP data of a constrained controller and the members it needs.
void EmitQpData(Module& m, const QpSolver& qp, const InputLimits& lim, bool soft_output) {
  const int n = qp.num_variables(), rows = qp.num_constraints();
  PNEUMID_CHECK(n > 0, "the controller's QP is not set up");
  m.qp_solver_ = m.dot_ = m.dot_strided_ = m.gemv_col_ = true;
  m.constants_ += fmt::format("#define PFX_QP_N {} /* QP variables */\n", n);
  m.constants_ += fmt::format("#define PFX_QP_M {} /* QP constraint rows */\n", rows);
  m.constants_ += fmt::format(
      "/* Iteration cap of one QP solve (0: 10 (n + finite sides) + 10); -D overrides it. A\n"
      "   solve that reaches it applies the clipped unconstrained move (within the limits). */\n"
      "#ifndef PFX_QP_MAX_ITERATIONS\n#define PFX_QP_MAX_ITERATIONS {}\n#endif\n",
      m.qp_max_iterations_);
  m.constants_ += fmt::format("#define PFX_QP_WARM_START {}\n", qp.options().warm_start ? 1 : 0);
  const double tol = m.is_float() ? std::max(qp.options().feasibility_tolerance, 1e-4)
                                  : qp.options().feasibility_tolerance;
  m.Scalar("QP_TOLERANCE", tol, "feasibility tolerance (units of the moves)");
  m.Array("qp_C", qp.constraint_matrix(), "QP constraint matrix C (column-major)");
  m.Array("qp_L", qp.cholesky_factor(),
          "Cholesky factor L of the QP Hessian H = L L' (column-major)");
  m.Array("qp_J0", qp.initial_basis(), "J0 = L^-T (column-major)");
  m.Array("qp_norm", qp.row_norms(), "norms of the rows of C");
  Eigen::VectorXd lbx = Eigen::VectorXd::Constant(n, -lim.du_max);
  Eigen::VectorXd ubx = Eigen::VectorXd::Constant(n, lim.du_max);
  if (soft_output) {
    lbx(n - 1) = 0.0;
    ubx(n - 1) = kInf;
  }
  m.Array("qp_lbx", lbx, "lower bounds of the moves (and the slack)");
  m.Array("qp_ubx", ubx, "upper bounds of the moves (and the slack)");
  const int m_rows = std::max(rows, 1);
  m.QpMember({Field::kReal, "J", n * n, "J = L^-T Q (column-major)"});
  m.QpMember({Field::kReal, "R", n * n, "R of J' N = [R; 0] (column-major)"});
  m.QpMember({Field::kReal, "x", n, "solution"});
  m.QpMember({Field::kReal, "u", n + 1, "multipliers of the active set"});
  m.QpMember({Field::kReal, "np", n, "normal of the constraint being added"});
  m.QpMember({Field::kReal, "d", n, "J' n_p"});
  m.QpMember({Field::kReal, "z", n, "primal direction"});
  m.QpMember({Field::kReal, "r", n, "dual direction"});
  m.QpMember({Field::kReal, "g", n, "linear term"});
  m.QpMember({Field::kReal, "cx", m_rows, "C x"});
  m.QpMember({Field::kReal, "lb", m_rows, "lower row bounds"});
  m.QpMember({Field::kReal, "ub", m_rows, "upper row bounds"});
  m.QpMember({Field::kInt, "active", n, "active constraint ids"});
  m.QpMember({Field::kInt, "warm", n, "active inequalities of the last solution"});
  m.QpMember({Field::kInt, "q", 0, "number of active constraints"});
  m.QpMember({Field::kInt, "nwarm", 0, "entries of warm"});
  m.QpMember({Field::kInt, "status", 0, "PFX_QP_SOLVED, ..."});
  m.QpMember({Field::kInt, "iterations", 0, "active-set changes of the last solve"});
  m.QpMember({Field::kByte, "is_active", 2 * (rows + n), "per constraint side"});
  m.Member({Field::kInt, "qp_failures", 0,
            "steps whose QP did not return PFX_QP_SOLVED (clipped unconstrained move applied)"});
}

// The row bounds of the move QP (move_qp_bounds.hpp) from the free response `free`.
std::string QpBoundsCode(const Module& m, bool u_rows, const InputLimits& lim, double y_min,
                         double y_max, int M, int P, const std::string& free) {
  std::string c;
  int row = 0;
  if (u_rows) {
    c += fmt::format(
        "  for (i = 0; i < {}; ++i) {{\n    s->qp.lb[i] = {} - s->u_prev;\n"
        "    s->qp.ub[i] = {} - s->u_prev;\n  }}\n",
        M, m.Literal(lim.u_min), m.Literal(lim.u_max));
    row += M;
  }
  if (std::isfinite(y_min)) {
    c += fmt::format(
        "  for (i = 0; i < {0}; ++i) {{\n    s->qp.lb[{1} + i] = {2} - {3}[i];\n"
        "    s->qp.ub[{1} + i] = PFX_INF;\n  }}\n",
        P, row, m.Literal(y_min), free);
    row += P;
  }
  if (std::isfinite(y_max)) {
    c += fmt::format(
        "  for (i = 0; i < {0}; ++i) {{\n    s->qp.lb[{1} + i] = -PFX_INF;\n"
        "    s->qp.ub[{1} + i] = {2} - {3}[i];\n  }}\n",
        P, row, m.Literal(y_max), free);
  }
  return c;
}

std::string RamHint(ControllerType type) {
  switch (type) {
    case ControllerType::kDmc:
      return "it grows with the model horizon N and P, and with P M for QDMC";
    case ControllerType::kGpc:
      return "it grows with the prediction horizon N2";
    case ControllerType::kMpc:
      return "it grows with the model order and, constrained, with P M";
    case ControllerType::kPid:
      return "a PID needs a few values";
  }
  return "";
}

void GeneratePid(const PidController& c, Module& m) {
  const PidOptions& o = c.options();
  const PidGains& g = o.gains;
  const double Ts = c.Ts(), Tt = c.tracking_time();
  const bool integral = std::isfinite(g.Ti), derivative = g.Td > 0.0;
  const double nts = o.derivative_filter * Ts;
  m.Scalar("KC", g.Kc, "proportional gain Kc");
  m.Scalar("B", o.setpoint_weight, "set-point weight b");
  m.Scalar("KR", g.Kc * (o.setpoint_weight - 1.0), "Kc (b - 1), for the bumpless reset");
  if (integral) m.Scalar("CI", g.Kc * Ts / g.Ti, "Kc Ts / Ti");
  const bool feedforward = o.velocity_feedforward != 0.0;
  if (feedforward) m.Scalar("KV", o.velocity_feedforward / Ts, "Kff / Ts (velocity feed-forward)");
  if (derivative) {
    m.Scalar("AD", g.Td / (g.Td + nts), "Td / (Td + N Ts)");
    m.Scalar("BD", g.Kc * g.Td * o.derivative_filter / (g.Td + nts), "Kc Td N / (Td + N Ts)");
  }
  const bool tracking = integral && Tt > 0.0;
  if (tracking) m.Scalar("CT", Ts / Tt, "Ts / Tt (back-calculation)");
  m.Member({Field::kReal, "integral", 0, "I"});
  m.Member({Field::kReal, "derivative", 0, "D (filtered, on y)"});
  m.Member({Field::kReal, "y_prev", 0, "last measurement"});
  m.Member({Field::kReal, "u_prev", 0, "last input"});
  if (feedforward) m.Member({Field::kReal, "r_prev", 0, "last set-point"});
  EmitClip(m, o.limits);
  m.code_ += R"C(void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {
  s->integral = u0 - PFX_KR * y0;
  s->derivative = PFX_ZERO;
  s->y_prev = y0;
  s->u_prev = u0;
)C";
  if (feedforward) m.code_ += "  s->r_prev = y0;\n";
  m.code_ += R"C(}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {
)C";
  if (integral) m.code_ += "  const PFX_real e = setpoint - measurement;\n";
  m.code_ += "  const PFX_real p = PFX_KC * (PFX_B * setpoint - measurement);\n  PFX_real v, u;\n";
  if (derivative)
    m.code_ += "  s->derivative = PFX_AD * s->derivative - PFX_BD * (measurement - s->y_prev);\n";
  m.code_ += "  v = p + s->integral + s->derivative;\n";
  if (feedforward) m.code_ += "  v += PFX_KV * (setpoint - s->r_prev);\n";
  m.code_ += "  u = PFX_clip(v, s->u_prev);\n";
  if (integral)
    m.code_ += tracking ? "  s->integral += PFX_CI * e + PFX_CT * (u - v);\n"
                        : "  s->integral += PFX_CI * e;\n";
  if (feedforward) m.code_ += "  s->r_prev = setpoint;\n";
  m.code_ += R"C(  s->y_prev = measurement;
  s->u_prev = u;
  return u;
}

void PFX_applied(PFX_state* s, PFX_real u) {
  const PFX_real delta = u - s->u_prev;
  if (delta == PFX_ZERO || !PFX_ISFINITE(delta)) return;
)C";
  if (tracking) m.code_ += "  s->integral += PFX_CT * delta;\n";
  m.code_ += "  s->u_prev = u;\n}\n";
}

void GenerateDmc(const DmcController& c, Module& m) {
  const DmcOptions& o = c.options();
  const int P = o.P, M = o.M;
  const int N = static_cast<int>(c.step_coefficients().size()) - 1;
  m.dot_ = true;
  m.Array("step_response", c.step_coefficients(), "step response s_0..s_N");
  m.Array("gain", c.gain().transpose(), "k', the first row of (A'QA + lambda R)^-1 A'Q");
  m.Scalar("GAIN_SUM", c.gain_sum(), "sum of k'");
  m.Member({Field::kReal, "yhat", N + 1, "prediction yhat_0..yhat_N"});
  m.Member({Field::kReal, "free", P, "free response f_1..f_P"});
  m.Member({Field::kReal, "u_prev", 0, "last input"});
  m.Member({Field::kReal, "last_du", 0, "last move"});
  const bool soft = std::isfinite(o.y_min) || std::isfinite(o.y_max);
  const bool u_rows = std::isfinite(o.limits.u_min) || std::isfinite(o.limits.u_max);
  if (o.constrained) {
    m.Array("AtQ", c.weighted_dynamic_matrix_transpose(), "A'Q (M x P, column-major)");
    m.Scalar("RHO1", o.slack_linear_weight, "linear slack weight");
    m.Member({Field::kReal, "err", P, "w - f"});
    EmitQpData(m, c.qp_solver(), o.limits, soft);
  }
  EmitClip(m, o.limits);
  m.code_ += fmt::format(R"C(void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {{
  int i;
  for (i = 0; i <= {0}; ++i) s->yhat[i] = y0;
  for (i = 0; i < {1}; ++i) s->free[i] = y0;
  s->u_prev = u0;
  s->last_du = PFX_ZERO;
{2}}}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {{
  const PFX_real bias = measurement - s->yhat[0];
  PFX_real du, u;
  int i;
  for (i = 0; i < {1}; ++i) s->free[i] = s->yhat[i + 1] + bias;
  du = PFX_GAIN_SUM * setpoint - PFX_dot(PFX_gain, s->free, {1});
)C",
                         N, P, o.constrained ? "  s->qp_failures = 0;\n  s->qp.nwarm = 0;\n" : "");
  if (o.constrained) {
    m.code_ += fmt::format(
        "  for (i = 0; i < {0}; ++i) s->err[i] = setpoint - s->free[i];\n"
        "  PFX_gemv_col(PFX_AtQ, {1}, {1}, {0}, s->err, s->qp.g, 0, -PFX_ONE);\n",
        P, M);
    if (soft) m.code_ += fmt::format("  s->qp.g[{}] = PFX_RHO1;\n", M);
    m.code_ += QpBoundsCode(m, u_rows, o.limits, o.y_min, o.y_max, M, P, "s->free");
    m.code_ +=
        "  if (PFX_qp_solve(&s->qp) == PFX_QP_SOLVED)\n    du = s->qp.x[0];\n  else\n"
        "    ++s->qp_failures;\n";
  }
  m.code_ += fmt::format(R"C(  u = PFX_clip(s->u_prev + du, s->u_prev);
  du = u - s->u_prev;
  for (i = 0; i < {0}; ++i) s->yhat[i] = s->yhat[i + 1] + PFX_step_response[i + 1] * du;
  s->yhat[{0}] += PFX_step_response[{0}] * du;
  s->u_prev = u;
  s->last_du = du;
  return u;
}}

void PFX_applied(PFX_state* s, PFX_real u) {{
  const PFX_real delta = u - s->u_prev;
  int i;
  if (delta == PFX_ZERO || !PFX_ISFINITE(delta)) return;
  for (i = 0; i < {0}; ++i) s->yhat[i] += PFX_step_response[i + 1] * delta;
  s->yhat[{0}] += PFX_step_response[{0}] * delta;
  s->u_prev = u;
  s->last_du += delta;
}}
)C",
                         N);
}

void GenerateGpc(const GpcController& c, Module& m) {
  const Eigen::MatrixXd& F = c.f_matrix();
  const Eigen::MatrixXd& Gamma = c.gamma_matrix();
  const Eigen::VectorXd& T = c.t_polynomial();
  const int rows = static_cast<int>(F.rows());
  const int nF = static_cast<int>(F.cols()), nG = static_cast<int>(Gamma.cols());
  const int nT = static_cast<int>(T.size());
  const int ny = static_cast<int>(c.y_history_length());
  const int nu = static_cast<int>(c.move_history_length());
  m.dot_ = m.gemv_col_ = true;
  m.Array("F", F, "F_j rows acting on y_f(t), y_f(t-1), ... (column-major)");
  m.Array("Gamma", Gamma, "Gamma_j rows acting on Du_f(t-1), ... (column-major)");
  m.Array("T", T, "observer polynomial T (ascending powers of q^-1)");
  m.Array("gain", c.gain().transpose(), "k', the first row of (G'G + lambda I)^-1 G'");
  m.Scalar("GAIN_SUM", c.gain_sum(), "sum of k'");
  m.Scalar("T_SUM", T.sum(), "T(1)");
  m.Member({Field::kReal, "yf", ny, "y_f(t), y_f(t-1), ..."});
  m.Member({Field::kReal, "duf", nu, "Du_f(t-1), Du_f(t-2), ..."});
  m.Member({Field::kReal, "free", rows, "free response"});
  m.Member({Field::kReal, "u_prev", 0, "last input"});
  m.Member({Field::kReal, "last_du", 0, "last move"});
  // Single precision: the free response from the deviations y_f(t-i) - y_f(t),
  // with du = (sum k)(w - T(1) y_f(t)) - k'(F (y_f - y_f(t)) + Gamma Du_f),
  // which is the same as every row F_j sums to T(1) (T = E_j Delta A + q^-j F_j
  // at q = 1), without the cancellation of k' F y_f against (sum k) w.
  const bool deviation = m.is_float();
  std::string free =
      fmt::format("  PFX_gemv_col(PFX_F, {0}, {0}, {1}, s->yf, s->free, 0, PFX_ONE);\n", rows, nF);
  std::string move = "  du = PFX_GAIN_SUM * setpoint - PFX_dot(PFX_gain, s->free, {2});\n";
  if (deviation) {
    const double t1 = T.sum();
    for (int r = 0; r < rows; ++r)
      PNEUMID_CHECK(
          std::abs(F.row(r).sum() - t1) <= 1e-9 * (F.row(r).cwiseAbs().sum() + std::abs(t1)),
          "GPC: row {} of F sums to {}, not T(1) = {}", r, F.row(r).sum(), t1);
    m.Member({Field::kReal, "dyf", nF, "y_f(t-i) - y_f(t)"});
    free = fmt::format(
        "  for (i = 0; i < {1}; ++i) s->dyf[i] = s->yf[i] - s->yf[0];\n"
        "  PFX_gemv_col(PFX_F, {0}, {0}, {1}, s->dyf, s->free, 0, PFX_ONE);\n",
        rows, nF);
    move =
        "  du = PFX_GAIN_SUM * (setpoint - PFX_T_SUM * s->yf[0]) - PFX_dot(PFX_gain, s->free, "
        "{2});\n";
  }
  EmitClip(m, c.options().limits);
  m.code_ +=
      fmt::format(R"C(void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {{
  int i;
  for (i = 0; i < {0}; ++i) s->yf[i] = y0 / PFX_T_SUM;
  for (i = 0; i < {1}; ++i) s->duf[i] = PFX_ZERO;
  for (i = 0; i < {2}; ++i) s->free[i] = y0;
  s->u_prev = u0;
  s->last_du = PFX_ZERO;
}}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {{
  PFX_real yf = measurement, du, duf, u;
  int i;
  for (i = {0} - 1; i > 0; --i) s->yf[i] = s->yf[i - 1];
  for (i = 1; i < {3}; ++i) yf -= PFX_T[i] * s->yf[i];
  s->yf[0] = yf;
{6}  PFX_gemv_col(PFX_Gamma, {2}, {2}, {5}, s->duf, s->free, 1, PFX_ONE);
{7}  u = PFX_clip(s->u_prev + du, s->u_prev);
  du = u - s->u_prev;
  for (i = {1} - 1; i > 0; --i) s->duf[i] = s->duf[i - 1];
  duf = du;
  for (i = 1; i < {3}; ++i) duf -= PFX_T[i] * s->duf[i];
  s->duf[0] = duf;
  s->u_prev = u;
  s->last_du = du;
  return u;
}}

void PFX_applied(PFX_state* s, PFX_real u) {{
  const PFX_real delta = u - s->u_prev;
  if (delta == PFX_ZERO || !PFX_ISFINITE(delta)) return;
  s->duf[0] += delta;
  s->u_prev = u;
  s->last_du += delta;
}}
)C",
                  ny, nu, rows, nT, nF, nG, free, fmt::format(fmt::runtime(move), 0, 0, rows));
}

// The sizes and options the MPC's generated code depends on.
struct MpcCodeLayout {
  int P = 0, M = 0;
  int nx = 0;      // model states (delay states included)
  int nz = 0;      // augmented states
  int rows_F = 0;  // rows of F emitted: unconstrained, only the first move is used
  bool constrained = false;
  bool soft = false;    // a finite soft output bound
  bool u_rows = false;  // a finite bound on u
  // Single precision: the moves are computed from the deviation of the state
  // and input from the target's steady state (EmitMpcModelData).
  bool deviation = false;
};

MpcCodeLayout MakeMpcCodeLayout(const MpcController& c, const Module& m) {
  const MpcOptions& o = c.options();
  MpcCodeLayout layout;
  layout.P = o.P;
  layout.M = o.M;
  layout.nx = c.num_model_states();
  layout.nz = static_cast<int>(c.Az().rows());
  layout.constrained = c.constrained();
  layout.soft = std::isfinite(o.y_min) || std::isfinite(o.y_max);
  layout.u_rows = std::isfinite(o.limits.u_min) || std::isfinite(o.limits.u_max);
  layout.rows_F = layout.constrained ? layout.M : 1;
  layout.deviation = m.is_float();
  return layout;
}

// The cancellation the deviation form relies on, checked on the design: at a
// steady state on target the moves vanish, per unit target and per unit
// disturbance.
void CheckMovesVanishOnTarget(const MpcController& c, const MpcCodeLayout& layout) {
  const MpcOptions& o = c.options();
  const int nx = layout.nx;
  const Eigen::MatrixXd& Fz = c.moves_state();
  const Eigen::VectorXd xs0 = c.unit_steady_state();
  const double G0 = c.static_gain();
  const bool with_disturbance = layout.nz > nx;
  for (int i = 0; i < layout.M; ++i) {
    const double fx = Fz.row(i).head(nx).dot(xs0);
    const double fd = with_disturbance ? Fz(i, nx) : 0.0;
    double per_us = fx + c.moves_input()(i) + c.moves_setpoint()(i) * G0 + c.moves_target()(i);
    double per_d = 0.0;
    if (o.disturbance == DisturbanceModel::kOutput) per_d = fd + c.moves_setpoint()(i);
    if (o.disturbance == DisturbanceModel::kInput) per_d = fx + fd + c.moves_setpoint()(i) * G0;
    const double scale = Fz.row(i).cwiseAbs().sum() * (1.0 + xs0.cwiseAbs().maxCoeff()) +
                         std::abs(c.moves_input()(i)) +
                         std::abs(c.moves_setpoint()(i)) * (1.0 + std::abs(G0)) +
                         std::abs(c.moves_target()(i));
    PNEUMID_CHECK(std::abs(per_us) <= 1e-8 * scale && std::abs(per_d) <= 1e-8 * scale,
                  "the MPC's moves do not vanish at a steady state on target (row {}: {} per "
                  "unit target, {} per unit disturbance)",
                  i, per_us, per_d);
  }
}

// The model, observer and unconstrained-move tables and the state members.
void EmitMpcModelData(const MpcController& c, const MpcCodeLayout& layout, Module& m) {
  const int nx = layout.nx, nz = layout.nz, rows_F = layout.rows_F;
  m.dot_ = m.gemv_col_ = true;
  m.Array("Az", c.Az(), "augmented A (column-major)");
  m.Array("Bz", c.Bz(), "augmented B");
  m.Array("Cz", c.Cz().transpose(), "augmented C");
  m.Array("L", c.kalman_gain(), "Kalman gain");
  // Single precision: the moves are computed from the deviation of the state
  // and input from the target's steady state, Fz (z - z_s) + Fu (u - u_s) (the
  // terms Fz z_s + Fu u_s + Fr r + Fs u_s cancel exactly: no move is optimal
  // at a steady state on target), so that the rounding of the gains causes no
  // bias that the input's integrator would accumulate; xs and G are those of
  // the rounded A, B, C, for the same reason.
  Eigen::VectorXd xs = c.unit_steady_state();
  double G = c.static_gain();
  if (layout.deviation) {
    const Eigen::MatrixXd A = c.Az().topLeftCorner(nx, nx).cast<float>().cast<double>();
    const Eigen::VectorXd B = c.Bz().head(nx).cast<float>().cast<double>();
    const Eigen::RowVectorXd C = c.Cz().head(nx).cast<float>().cast<double>();
    xs = (Eigen::MatrixXd::Identity(nx, nx) - A).partialPivLu().solve(B);
    G = C.dot(xs);
    CheckMovesVanishOnTarget(c, layout);
  }
  m.Array("xs", xs, "(I - A)^-1 B");
  m.Scalar("G", G, "static gain C (I - A)^-1 B");
  m.Array("Fz", c.moves_state().topRows(rows_F), "moves per state estimate (column-major)");
  m.Array("Fu", c.moves_input().head(rows_F), "moves per u_{k-1}");
  if (!layout.deviation) {
    m.Array("Fr", c.moves_setpoint().head(rows_F), "moves per set-point");
    m.Array("Fs", c.moves_target().head(rows_F), "moves per target input u_s");
  }
  m.Member({Field::kReal, "z_prior", nz, "z_k|k-1"});
  m.Member({Field::kReal, "z_post", nz, "z_k|k"});
  m.Member({Field::kReal, "z_tmp", nz, "work"});
  m.Member({Field::kReal, "moves", rows_F, "planned moves"});
  m.Member({Field::kReal, "u_prev", 0, "last input"});
  m.Member({Field::kReal, "us", 0, "target input u_s"});
}

// The constrained form's tables (free response, QP linear term) and the QP.
void EmitMpcQpData(const MpcController& c, const MpcCodeLayout& layout, Module& m) {
  const MpcOptions& o = c.options();
  m.dot_strided_ = true;
  if (layout.soft) {
    m.Array("Psi", c.free_response_matrix(), "Psi (P x nz, column-major)");
    m.Array("Ups", c.input_response(), "Ups (P)");
    m.Member({Field::kReal, "free", layout.P, "free response"});
    m.Array("Theta", c.dynamic_matrix(), "Theta (P x M, column-major)");
  }
  m.Array("Gz", c.gradient_state(), "QP linear term per state (column-major)");
  m.Array("Gu", c.gradient_input(), "QP linear term per u_{k-1}");
  if (!layout.deviation) {
    m.Array("Gr", c.gradient_setpoint(), "QP linear term per set-point");
    m.Array("Gs", c.gradient_target(), "QP linear term per target input");
  }
  m.Scalar("RHO1", o.slack_linear_weight, "linear slack weight");
  m.Member({Field::kInt, "last_active", 0, "the last step solved the QP"});
  EmitQpData(m, c.qp_solver(), o.limits, layout.soft);
}

// Reset: the observer at the steady state of u0 (mpc.cpp).
std::string MpcResetCode(DisturbanceModel disturbance, int nx) {
  switch (disturbance) {
    case DisturbanceModel::kOutput:
      return fmt::format(
          "  for (i = 0; i < {0}; ++i) s->z_prior[i] = PFX_xs[i] * u0;\n"
          "  s->z_prior[{0}] = y0 - PFX_dot(PFX_Cz, s->z_prior, {0});\n",
          nx);
    case DisturbanceModel::kInput:
      return fmt::format(
          "  {{\n    const PFX_real d = y0 / PFX_G - u0;\n"
          "    for (i = 0; i < {0}; ++i) s->z_prior[i] = PFX_xs[i] * (u0 + d);\n"
          "    s->z_prior[{0}] = d;\n  }}\n",
          nx);
    case DisturbanceModel::kNone:
      return fmt::format(
          "  (void)y0;\n  for (i = 0; i < {0}; ++i) s->z_prior[i] = PFX_xs[i] * u0;\n", nx);
  }
  return "";
}

// The target input u_s from the set-point and the disturbance estimate.
std::string MpcTargetCode(DisturbanceModel disturbance, int nx) {
  switch (disturbance) {
    case DisturbanceModel::kOutput:
      return fmt::format("  us = (setpoint - s->z_post[{}]) / PFX_G;\n", nx);
    case DisturbanceModel::kInput:
      return fmt::format("  us = setpoint / PFX_G - s->z_post[{}];\n", nx);
    case DisturbanceModel::kNone:
      return "  us = setpoint / PFX_G;\n";
  }
  return "";
}

// The unconstrained moves, in the deviation form or from Fz z + Fu u_{k-1} + Fr r + Fs u_s.
std::string MpcMovesCode(DisturbanceModel disturbance, const MpcCodeLayout& layout) {
  const int nx = layout.nx;
  if (!layout.deviation) {
    return fmt::format(
        "  PFX_gemv_col(PFX_Fz, {0}, {0}, {1}, s->z_post, s->moves, 0, PFX_ONE);\n"
        "  for (i = 0; i < {0}; ++i)\n"
        "    s->moves[i] += PFX_Fu[i] * s->u_prev + PFX_Fr[i] * setpoint + PFX_Fs[i] * us;\n",
        layout.rows_F, layout.nz);
  }
  std::string moves;
  switch (disturbance) {
    case DisturbanceModel::kOutput:
      moves = fmt::format(
          "  for (i = 0; i < {0}; ++i) s->z_tmp[i] = s->z_post[i] - PFX_xs[i] * us;\n"
          "  s->z_tmp[{0}] = PFX_ZERO;\n",
          nx);
      break;
    case DisturbanceModel::kInput:
      moves = fmt::format(
          "  for (i = 0; i < {0}; ++i) s->z_tmp[i] = s->z_post[i] - PFX_xs[i] * (us + "
          "s->z_post[{0}]);\n"
          "  s->z_tmp[{0}] = PFX_ZERO;\n",
          nx);
      break;
    case DisturbanceModel::kNone:
      moves = fmt::format(
          "  for (i = 0; i < {0}; ++i) s->z_tmp[i] = s->z_post[i] - PFX_xs[i] * us;\n", nx);
      break;
  }
  moves += fmt::format(
      "  PFX_gemv_col(PFX_Fz, {0}, {0}, {1}, s->z_tmp, s->moves, 0, PFX_ONE);\n"
      "  for (i = 0; i < {0}; ++i) s->moves[i] += PFX_Fu[i] * (s->u_prev - us);\n",
      layout.rows_F, layout.nz);
  return moves;
}

// PFX_reset, and PFX_step up to the unconstrained moves.
std::string MpcResetAndMovesCode(const MpcController& c, const MpcCodeLayout& layout) {
  const DisturbanceModel disturbance = c.options().disturbance;
  return fmt::format(
      R"C(void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {{
  int i;
{0}  for (i = 0; i < {1}; ++i) s->z_post[i] = s->z_prior[i];
  for (i = 0; i < {2}; ++i) s->moves[i] = PFX_ZERO;
  s->u_prev = u0;
  s->us = u0;
{3}}}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {{
  const PFX_real innovation = measurement - PFX_dot(PFX_Cz, s->z_prior, {1});
  PFX_real us, u;
  int i;
  for (i = 0; i < {1}; ++i) s->z_post[i] = s->z_prior[i] + PFX_L[i] * innovation;
{4}{5})C",
      MpcResetCode(disturbance, layout.nx), layout.nz, layout.rows_F,
      layout.constrained ? "  s->qp_failures = 0;\n  s->last_active = 0;\n  s->qp.nwarm = 0;\n"
                         : "",
      MpcTargetCode(disturbance, layout.nx), MpcMovesCode(disturbance, layout));
}

// " || "-joined conditions.
std::string JoinedWithOr(const std::vector<std::string>& tests) {
  std::string cond;
  for (std::size_t k = 0; k < tests.size(); ++k) cond += (k ? " || " : "") + tests[k];
  return cond;
}

// UnconstrainedMovesFeasible(): opens a block that sets `feasible`.
std::string MpcFeasibilityCode(const MpcOptions& o, const MpcCodeLayout& layout, const Module& m) {
  const InputLimits& lim = o.limits;
  std::vector<std::string> tests;
  if (std::isfinite(lim.du_max))
    tests.push_back(fmt::format("!(PFX_FABS(du) <= {})", m.Literal(lim.du_max)));
  if (std::isfinite(lim.u_min)) tests.push_back(fmt::format("!(uj >= {})", m.Literal(lim.u_min)));
  if (std::isfinite(lim.u_max)) tests.push_back(fmt::format("!(uj <= {})", m.Literal(lim.u_max)));
  std::string check = "  {\n    int feasible = 1;\n";
  if (!tests.empty()) {
    check += fmt::format(
        "    PFX_real uj = s->u_prev;\n    for (i = 0; i < {} && feasible; ++i) {{\n"
        "      const PFX_real du = s->moves[i];\n      uj += du;\n"
        "      if ({}) feasible = 0;\n    }}\n",
        layout.M, JoinedWithOr(tests));
  }
  if (layout.soft) {
    std::vector<std::string> ytests;
    if (std::isfinite(o.y_min)) ytests.push_back(fmt::format("!(y >= {})", m.Literal(o.y_min)));
    if (std::isfinite(o.y_max)) ytests.push_back(fmt::format("!(y <= {})", m.Literal(o.y_max)));
    check += fmt::format(
        "    for (i = 0; i < {0} && feasible; ++i) {{\n"
        "      const int n = i + 1 < {1} ? i + 1 : {1};\n"
        "      const PFX_real y = s->free[i] + PFX_dot_strided(PFX_Theta + i, {0}, s->moves, "
        "n);\n"
        "      if ({2}) feasible = 0;\n    }}\n",
        layout.P, layout.M, JoinedWithOr(ytests));
  }
  return check;
}

// Each line of `code` indented by `indent`.
std::string Indented(const std::string& code, const std::string& indent) {
  std::string indented;
  std::size_t start = 0;
  while (start < code.size()) {
    const std::size_t end = code.find('\n', start);
    indented += indent + code.substr(start, end - start + 1);
    start = end + 1;
  }
  return indented;
}

// The QP of a step whose unconstrained moves are infeasible, closing the
// block MpcFeasibilityCode opened.
std::string MpcQpSolveCode(const MpcOptions& o, const MpcCodeLayout& layout, const Module& m) {
  const int M = layout.M, nz = layout.nz;
  std::string code = "    if (!feasible) {\n      s->last_active = 1;\n";
  code +=
      layout.deviation
          ? fmt::format(
                "      PFX_gemv_col(PFX_Gz, {0}, {0}, {1}, s->z_tmp, s->qp.g, 0, PFX_ONE);\n"
                "      for (i = 0; i < {0}; ++i) s->qp.g[i] += PFX_Gu[i] * (s->u_prev - us);\n",
                M, nz)
          : fmt::format(
                "      PFX_gemv_col(PFX_Gz, {0}, {0}, {1}, s->z_post, s->qp.g, 0, PFX_ONE);\n"
                "      for (i = 0; i < {0}; ++i)\n"
                "        s->qp.g[i] += PFX_Gu[i] * s->u_prev + PFX_Gr[i] * setpoint + PFX_Gs[i] "
                "* us;\n",
                M, nz);
  if (layout.soft) code += fmt::format("      s->qp.g[{}] = PFX_RHO1;\n", M);
  // The bounds code indented one level further.
  code += Indented(
      QpBoundsCode(m, layout.u_rows, o.limits, o.y_min, o.y_max, M, layout.P, "s->free"), "    ");
  code += fmt::format(
      "      if (PFX_qp_solve(&s->qp) == PFX_QP_SOLVED)\n"
      "        for (i = 0; i < {}; ++i) s->moves[i] = s->qp.x[i];\n"
      "      else\n        ++s->qp_failures;\n    }}\n  }}\n",
      M);
  return code;
}

// The constrained part of PFX_step: the free response, the feasibility of
// the unconstrained moves, and the QP when they are not.
std::string MpcConstrainedStepCode(const MpcController& c, const MpcCodeLayout& layout,
                                   const Module& m) {
  const MpcOptions& o = c.options();
  std::string code = "  s->last_active = 0;\n";
  if (layout.soft)
    code += fmt::format(
        "  PFX_gemv_col(PFX_Psi, {0}, {0}, {1}, s->z_post, s->free, 0, PFX_ONE);\n"
        "  for (i = 0; i < {0}; ++i) s->free[i] += PFX_Ups[i] * s->u_prev;\n",
        layout.P, layout.nz);
  code += MpcFeasibilityCode(o, layout, m);
  code += MpcQpSolveCode(o, layout, m);
  return code;
}

// The end of PFX_step (clip, observer prediction) and PFX_applied.
std::string MpcStepEndAndAppliedCode(int nz) {
  return fmt::format(R"C(  u = PFX_clip(s->u_prev + s->moves[0], s->u_prev);
  PFX_gemv_col(PFX_Az, {0}, {0}, {0}, s->z_post, s->z_tmp, 0, PFX_ONE);
  for (i = 0; i < {0}; ++i) s->z_prior[i] = s->z_tmp[i] + PFX_Bz[i] * u;
  s->u_prev = u;
  s->us = us;
  return u;
}}

void PFX_applied(PFX_state* s, PFX_real u) {{
  const PFX_real delta = u - s->u_prev;
  int i;
  if (delta == PFX_ZERO || !PFX_ISFINITE(delta)) return;
  for (i = 0; i < {0}; ++i) s->z_prior[i] += PFX_Bz[i] * delta;
  s->u_prev = u;
}}
)C",
                     nz);
}

void GenerateMpc(const MpcController& c, Module& m) {
  PNEUMID_CHECK(!c.integrating(),
                "generated C of an MPC on an integrating model is not available (its target "
                "and reset have no static gain to use); generate the PD (--controller pid) for a "
                "position loop");
  const MpcCodeLayout layout = MakeMpcCodeLayout(c, m);
  EmitMpcModelData(c, layout, m);
  if (layout.constrained) EmitMpcQpData(c, layout, m);
  EmitClip(m, c.options().limits);
  m.code_ += MpcResetAndMovesCode(c, layout);
  if (layout.constrained) m.code_ += MpcConstrainedStepCode(c, layout, m);
  m.code_ += MpcStepEndAndAppliedCode(layout.nz);
}

// Makes the entry points generated so far (PFX_reset, PFX_step, PFX_applied,
// PFX_clip) static functions named PFX_<stem>reset, ..., so that a layer
// around them can define its own.
void HideEntryPoints(Module& m, const std::string& stem) {
  auto replace_all = [&](const std::string& from, const std::string& to) {
    std::string out;
    std::size_t pos = 0;
    for (std::size_t at; (at = m.code_.find(from, pos)) != std::string::npos;
         pos = at + from.size())
      out.append(m.code_, pos, at - pos).append(to);
    out.append(m.code_, pos, std::string::npos);
    m.code_ = std::move(out);
  };
  for (const char* name : {"reset", "step", "applied", "clip"})
    replace_all(fmt::format("PFX_{}(", name), fmt::format("PFX_{}{}(", stem, name));
  replace_all(fmt::format("\nvoid PFX_{}reset(", stem),
              fmt::format("\nstatic void PFX_{}reset(", stem));
  replace_all(fmt::format("\nvoid PFX_{}applied(", stem),
              fmt::format("\nstatic void PFX_{}applied(", stem));
  replace_all(fmt::format("\nPFX_real PFX_{}step(", stem),
              fmt::format("\nstatic PFX_real PFX_{}step(", stem));
}

// PFX_<name>_eval(u) and, for a monotone map, PFX_<name>_inverse(y): the
// piecewise-linear map f and its inverse as StaticMap::Evaluate and
// StaticMap::Inverse compute them (same segment search, same expressions).
void EmitStaticMap(Module& m, const StaticMap& map, const std::string& name,
                   const std::string& what, bool eval, bool inverse) {
  const int n = static_cast<int>(map.size());
  const Eigen::Map<const Eigen::VectorXd> u(map.u().data(), n), y(map.y().data(), n);
  m.Array(name + "_u", u, what + ": knots u");
  if (eval) m.Array(name + "_y", y, what + ": values y");
  std::string ends;
  if (map.extrapolation() == StaticMapExtrapolation::kClamp) {
    ends =
        fmt::format("    return u <= PFX_{0}_u[0] ? PFX_{0}_y[0] : PFX_{0}_y[{1}];\n", name, n - 1);
  } else {
    ends = fmt::format(
        "    i = u <= PFX_{0}_u[0] ? 0 : {1};\n"
        "    if (PFX_{0}_y[i + 1] == PFX_{0}_y[i]) return PFX_{0}_y[i];\n"
        "    return PFX_{0}_y[i] + (PFX_{0}_y[i + 1] - PFX_{0}_y[i]) * (u - PFX_{0}_u[i]) /\n"
        "           (PFX_{0}_u[i + 1] - PFX_{0}_u[i]);\n",
        name, n - 2);
  }
  if (eval)
    m.code_ += fmt::format(
        R"C(/* {2} (StaticMap::Evaluate, {3} extrapolation). */
static PFX_real PFX_{0}_eval(PFX_real u) {{
  int i;
  if (u != u) return u;
  if (u <= PFX_{0}_u[0] || u >= PFX_{0}_u[{1}]) {{
{4}  }}
  i = 0;
  while (PFX_{0}_u[i + 1] <= u) ++i;
  return PFX_{0}_y[i] + (PFX_{0}_y[i + 1] - PFX_{0}_y[i]) * (u - PFX_{0}_u[i]) /
         (PFX_{0}_u[i + 1] - PFX_{0}_u[i]);
}}

)C",
        name, n - 1, what, ToString(map.extrapolation()), ends);
  if (!inverse) return;
  PNEUMID_CHECK(map.IsMonotone(), "the {} ({}) is not monotone: it has no inverse", what,
                map.Describe());
  const double sign = map.Direction() == Monotonicity::kIncreasing ? 1.0 : -1.0;
  Eigen::VectorXd ys = sign * y;
  int low_end = 0, high_start = n - 1;
  while (low_end + 1 < n && ys[low_end + 1] == ys[0]) ++low_end;
  while (high_start > 0 && ys[high_start - 1] == ys[n - 1]) --high_start;
  m.Array(name + "_ys", ys, what + ": values times the map's direction (+-1)");
  m.code_ += fmt::format(
      R"C(/* The inverse of the {2} (StaticMap::Inverse): y beyond the range gives the
   end of the input range where the output starts to move. */
static PFX_real PFX_{0}_inverse(PFX_real y) {{
  const PFX_real v = {3} * y;
  int i;
  if (v <= PFX_{0}_ys[0]) return PFX_{0}_u[{4}];
  if (v >= PFX_{0}_ys[{1}]) return PFX_{0}_u[{5}];
  i = 1;
  while (PFX_{0}_ys[i] < v) ++i;
  return PFX_{0}_u[i - 1] + (PFX_{0}_u[i] - PFX_{0}_u[i - 1]) * (v - PFX_{0}_ys[i - 1]) /
         (PFX_{0}_ys[i] - PFX_{0}_ys[i - 1]);
}}

)C",
      name, n - 1, what, m.Literal(sign), low_end, high_start);
}

// InverseMapController: u = clip(f^-1(inner(r, y))), the inner controller
// told f(u) when it differs from its request.
void GenerateInverseMap(const InverseMapController& c, Module& m, const std::string& stem) {
  const std::string map = stem + "imap";
  EmitStaticMap(m, c.map(), map, "input map f (u -> v)", true, true);
  EmitClip(m, c.limits());
  m.Member({Field::kReal, stem + "u_prev", 0, "last input u (input map layer)"});
  m.Member({Field::kReal, stem + "v", 0, "inner controller's request v"});
  m.code_ += fmt::format(R"C(void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {{
  s->{0}u_prev = u0;
  s->{0}v = PFX_{1}_eval(u0);
  PFX_{0}reset(s, s->{0}v, y0);
}}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {{
  PFX_real u_inv, u, v_applied;
  s->{0}v = PFX_{0}step(s, setpoint, measurement);
  u_inv = PFX_ISFINITE(s->{0}v) ? PFX_{1}_inverse(s->{0}v) : s->{0}u_prev;
  u = PFX_clip(u_inv, s->{0}u_prev);
  v_applied = PFX_{1}_eval(u);
  if (v_applied != s->{0}v) PFX_{0}applied(s, v_applied);
  s->{0}u_prev = u;
  return u;
}}

void PFX_applied(PFX_state* s, PFX_real u) {{
  if (u == s->{0}u_prev || !PFX_ISFINITE(u)) return;
  s->{0}u_prev = u;
  PFX_{0}applied(s, PFX_{1}_eval(u));
}}
)C",
                         stem, map);
}

// ModulatedController: first-order sigma-delta across the input gaps
// (duty_modulator.hpp), the gaps as literals.
void GenerateModulator(const ModulatedController& c, Module& m, const std::string& stem) {
  const DutyModulator& mod = c.modulator();
  m.Member({Field::kReal, stem + "err", 0, "carried modulation error (input units)"});
  m.Member({Field::kReal, stem + "v", 0, "inner controller's request v"});
  // A request at or beyond an end of the input range: that end, nothing
  // carried; else a = w clipped to the range unless a gap holds w.
  struct End {
    double value;
    const char* at_or_beyond;  // comparison of the request with the end
    const char* beyond;        // comparison of the clipped input with the end
  };
  const End ends[] = {{mod.u_min(), "<=", "<"}, {mod.u_max(), ">=", ">"}};
  std::string clip;
  for (const End& e : ends)
    if (std::isfinite(e.value))
      clip += fmt::format(
          "  if (s->{0}v {1} {2}) {{\n    s->{0}err = PFX_ZERO;\n    return {2};\n  }}\n", stem,
          e.at_or_beyond, m.Literal(e.value));
  clip += "  w = s->" + stem + "v + s->" + stem + "err;\n  a = w;\n";
  for (const End& e : ends)
    if (std::isfinite(e.value))
      clip += fmt::format("  if (a {0} {1}) a = {1};\n", e.beyond, m.Literal(e.value));
  std::string chain;
  for (const InputGap& g : mod.gaps()) {
    chain += fmt::format("{0}if (w > {1} && w < {2}) a = (w - {1} < {2} - w) ? {1} : {2};\n",
                         chain.empty() ? "  " : "  else ", m.Literal(g.lo), m.Literal(g.hi));
  }
  m.code_ += fmt::format(R"C(void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {{
  s->{0}err = PFX_ZERO;
  s->{0}v = u0;
  PFX_{0}reset(s, u0, y0);
}}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {{
  PFX_real w, a, e;
  s->{0}v = PFX_{0}step(s, setpoint, measurement);
  if (!PFX_ISFINITE(s->{0}v)) return s->{0}v;
{3}{1}  e = w - a;
  s->{0}err = e < -{2} ? -{2} : ({2} < e ? {2} : e);
  return a;
}}

void PFX_applied(PFX_state* s, PFX_real u) {{
  if (PFX_ISFINITE(u) && PFX_FABS(u - s->{0}v) > {2}) PFX_{0}applied(s, u);
}}
)C",
                         stem, chain, m.Literal(mod.max_error()), clip);
}

// OutputMapController: the inner controller on g^-1(r), g^-1(y).
void GenerateOutputMap(const OutputMapController& c, Module& m, const std::string& stem) {
  const std::string map = stem + "omap";
  EmitStaticMap(m, c.map(), map, "monotone envelope of the output map g", false, true);
  m.code_ += fmt::format(R"C(void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {{
  PFX_{0}reset(s, u0, PFX_{1}_inverse(y0));
}}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {{
  return PFX_{0}step(s, PFX_{1}_inverse(setpoint), PFX_{1}_inverse(measurement));
}}

void PFX_applied(PFX_state* s, PFX_real u) {{ PFX_{0}applied(s, u); }}
)C",
                         stem, map);
}

// NarxLinearizingController: v = (p y + (1 - p) w - F(y)) / G(y), u = clip(f^-1(v)).
void GenerateNarxLinearization(const NarxLinearizingController& c, Module& m,
                               const std::string& stem) {
  const InputAffineNarx& model = c.model();
  const InputLimits& lim = c.limits();
  const auto& drift = model.drift_coefficients();
  const auto& gain = model.gain_coefficients();
  m.Array(stem + "drift", Eigen::Map<const Eigen::VectorXd>(drift.data(), drift.size()),
          "F(y) = y_scale sum_k F_k (y / y_scale)^k");
  m.Array(stem + "gain", Eigen::Map<const Eigen::VectorXd>(gain.data(), gain.size()),
          "G(y) = y_scale sum_k G_k (y / y_scale)^k");
  const double p = std::exp(-model.Ts() / c.time_constant());
  m.Scalar(internal::Upper(stem) + "P", p, "pole of the reference model, exp(-Ts / tau)");
  m.Scalar(internal::Upper(stem) + "Y_SCALE", model.y_scale(), "output scale of the NARX terms");
  m.macros_.insert(internal::Upper(stem) + "P");
  m.macros_.insert(internal::Upper(stem) + "Y_SCALE");
  std::string map_eval = "u", map_inverse = "v";
  if (model.map()) {
    EmitStaticMap(m, *model.map(), stem + "nmap", "NARX model's input map f", true, false);
    EmitStaticMap(m, *model.envelope(), stem + "nenv", "monotone envelope of the input map", false,
                  true);
    map_eval = fmt::format("PFX_{}nmap_eval(u)", stem);
    map_inverse = fmt::format("PFX_{}nenv_inverse(v)", stem);
  }
  EmitClip(m, lim);
  m.Member({Field::kReal, stem + "u_prev", 0, "last input u (NARX layer)"});
  m.Member({Field::kReal, stem + "y_last", 0, "last measurement"});
  m.Member({Field::kReal, stem + "w", 0, "inner controller's request w"});
  const std::string S = internal::Upper(stem);
  m.code_ += fmt::format(
      R"C(static PFX_real PFX_{0}poly(const PFX_real* c, int n, PFX_real y) {{
  const PFX_real z = y / PFX_{1}Y_SCALE;
  PFX_real sum = PFX_ZERO;
  while (n-- > 0) sum = sum * z + c[n];
  return PFX_{1}Y_SCALE * sum;
}}

static PFX_real PFX_{0}map(PFX_real u) {{ return {5}; }}
static PFX_real PFX_{0}inverse_map(PFX_real v) {{ return {6}; }}

/* w that the input u gives on the model from the last measurement. */
static PFX_real PFX_{0}applied_w(const PFX_state* s, PFX_real u) {{
  const PFX_real y = s->{0}y_last;
  return (PFX_{0}poly(PFX_{0}drift, {2}, y) + PFX_{0}poly(PFX_{0}gain, {3}, y) * PFX_{0}map(u) -
          PFX_{1}P * y) /
         (PFX_ONE - PFX_{1}P);
}}

void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {{
  s->{0}u_prev = u0;
  s->{0}y_last = y0;
  s->{0}w = y0;
  PFX_{0}reset(s, s->{0}w, y0);
}}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {{
  PFX_real u_target = s->{0}u_prev, u, w_applied;
  s->{0}y_last = measurement;
  s->{0}w = PFX_{0}step(s, setpoint, measurement);
  if (PFX_ISFINITE(s->{0}w) && PFX_ISFINITE(measurement)) {{
    const PFX_real target = PFX_{1}P * measurement + (PFX_ONE - PFX_{1}P) * s->{0}w;
    const PFX_real drift = PFX_{0}poly(PFX_{0}drift, {2}, measurement);
    const PFX_real gain = PFX_{0}poly(PFX_{0}gain, {3}, measurement);
    if (PFX_FABS(gain) > {4} * (PFX_ONE + PFX_FABS(drift))) {{
      u_target = PFX_{0}inverse_map((target - drift) / gain);
    }} else {{
      u_target = target > drift ? {7} : {8};
      if (!PFX_ISFINITE(u_target)) u_target = s->{0}u_prev;
    }}
  }}
  u = PFX_clip(u_target, s->{0}u_prev);
  w_applied = PFX_{0}applied_w(s, u);
  if (PFX_ISFINITE(w_applied) &&
      PFX_FABS(w_applied - s->{0}w) > {4} * (PFX_ONE + PFX_FABS(s->{0}w)))
    PFX_{0}applied(s, w_applied);
  s->{0}u_prev = u;
  return u;
}}

void PFX_applied(PFX_state* s, PFX_real u) {{
  PFX_real w;
  if (u == s->{0}u_prev || !PFX_ISFINITE(u)) return;
  s->{0}u_prev = u;
  w = PFX_{0}applied_w(s, u);
  if (PFX_ISFINITE(w)) PFX_{0}applied(s, w);
}}
)C",
      stem, S, drift.size(), gain.size(), m.Literal(1e-12), map_eval, map_inverse,
      m.Literal(lim.u_max), m.Literal(lim.u_min));
}

// The guard of Controller::Update (MeasurementGuard): a sample with a
// non-finite or out-of-range measurement or a non-finite set-point leaves the
// state untouched and returns the held (or safe) input.
void GenerateGuard(const Controller& c, Module& m) {
  const MeasurementGuard& g = c.measurement_guard();
  m.constants_ += fmt::format(
      "/* The range of valid measurements (MeasurementGuard); -D overrides it. */\n"
      "#ifndef PFX_Y_VALID_MIN\n#define PFX_Y_VALID_MIN {}\n#endif\n"
      "#ifndef PFX_Y_VALID_MAX\n#define PFX_Y_VALID_MAX {}\n#endif\n",
      std::isfinite(g.y_min) ? m.Literal(g.y_min) : "(-PFX_INF)",
      std::isfinite(g.y_max) ? m.Literal(g.y_max) : "PFX_INF");
  if (!std::isnan(g.safe_input))
    m.constants_ += fmt::format(
        "/* The input on a faulty sample (unset: hold the last input); -D overrides it. */\n"
        "#ifndef PFX_SAFE_INPUT\n#define PFX_SAFE_INPUT {}\n#endif\n",
        m.Literal(g.safe_input));
  m.Member({Field::kReal, "u_hold", 0, "last valid input (held on a faulty sample)"});
  m.Member({Field::kReal, "y_hold", 0, "last valid measurement (the law restarts there)"});
  m.Member({Field::kInt, "fault", 0, "fault of the last step: PFX_FAULT_NONE or another PFX_FAULT_ code"});
  m.Member({Field::kInt, "faults", 0, "faulty samples since the last reset"});
  m.code_ += R"C(void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0) {
  s->u_hold = u0;
  s->y_hold = y0;
  s->fault = PFX_FAULT_NONE;
  s->faults = 0;
  PFX_core_reset(s, u0, y0);
}

PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement) {
  int fault = PFX_FAULT_NONE;
  if (!PFX_ISFINITE(measurement)) {
    fault = PFX_FAULT_MEASUREMENT_NOT_FINITE;
  } else if (measurement < PFX_Y_VALID_MIN || measurement > PFX_Y_VALID_MAX) {
    fault = PFX_FAULT_MEASUREMENT_OUT_OF_RANGE;
  } else if (!PFX_ISFINITE(setpoint)) {
    fault = PFX_FAULT_SETPOINT_NOT_FINITE;
  } else {
    const PFX_real u = PFX_core_step(s, setpoint, measurement);
    if (PFX_ISFINITE(u)) {
      s->u_hold = u;
      s->y_hold = measurement;
      s->fault = PFX_FAULT_NONE;
      return u;
    }
    /* The law overflowed (a finite but huge measurement): its state may hold
       the overflow, so it restarts at rest at the held input. */
    fault = PFX_FAULT_OUTPUT_NOT_FINITE;
    PFX_core_reset(s, s->u_hold, s->y_hold);
  }
  s->fault = fault;
  if (s->faults < 2147483647) ++s->faults;
#ifdef PFX_SAFE_INPUT
  if (s->u_hold != PFX_SAFE_INPUT) {
    s->u_hold = PFX_SAFE_INPUT;
    PFX_core_applied(s, s->u_hold);
  }
#endif
  return s->u_hold;
}

void PFX_applied(PFX_state* s, PFX_real u) {
  if (!PFX_ISFINITE(u)) return;
  s->u_hold = u;
  PFX_core_applied(s, u);
}
)C";
}

// Work units (multiply-adds, comparisons, map segments) of one step outside
// the QP, and the QP's dimensions when there is one (RealTimeCertificate).
struct StepCost {
  double base = 0.0;
  const QpSolver* qp = nullptr;
};

// The step cost of each controller class; a layer adds its own and its inner
// controller's.
class StepCostVisitor final : public ControllerVisitor {
 public:
  explicit StepCostVisitor(StepCost* cost) : cost_(cost) {}

  void Visit(const PidController&) override { cost_->base += 30.0; }
  void Visit(const DmcController& dmc) override {
    const double N = static_cast<double>(dmc.step_coefficients().size());
    const double P = dmc.options().P, M = dmc.options().M;
    cost_->base += 2.0 * N + 2.0 * P + Dot(P) + 30.0;
    if (dmc.options().constrained) {
      cost_->base += Gemv(M, P) + 4.0 * P + 2.0 * M;
      cost_->qp = &dmc.qp_solver();
    }
  }
  void Visit(const GpcController& gpc) override {
    const double rows = static_cast<double>(gpc.f_matrix().rows());
    cost_->base += Gemv(rows, static_cast<double>(gpc.f_matrix().cols())) +
                   Gemv(rows, static_cast<double>(gpc.gamma_matrix().cols())) + Dot(rows) + rows +
                   2.0 * static_cast<double>(gpc.t_polynomial().size()) +
                   2.0 * static_cast<double>(gpc.y_history_length() + gpc.move_history_length()) +
                   30.0;
  }
  void Visit(const MpcController& mpc) override {
    const double nz = static_cast<double>(mpc.Az().rows());
    const double P = mpc.options().P, M = mpc.options().M;
    const double rows = mpc.constrained() ? M : 1.0;
    cost_->base += Gemv(nz, nz) + Gemv(rows, nz) + Dot(nz) + 6.0 * nz + 2.0 * rows + 30.0;
    if (mpc.constrained()) {
      // Free response, the feasibility test of the unconstrained moves, the
      // QP's linear term and row bounds.
      cost_->base += Gemv(P, nz) + Gemv(P, M) + Gemv(M, nz) + 4.0 * P + 4.0 * M;
      cost_->qp = &mpc.qp_solver();
    }
  }
  void Visit(const InverseMapController& layer) override {
    cost_->base += 3.0 * MapCost(layer.map()) + 10.0;
    layer.inner().Accept(*this);
  }
  void Visit(const OutputMapController& layer) override {
    cost_->base += 2.0 * MapCost(layer.map()) + 10.0;
    layer.inner().Accept(*this);
  }
  void Visit(const ModulatedController& layer) override {
    cost_->base += 4.0 * static_cast<double>(layer.modulator().gaps().size()) + 20.0;
    layer.inner().Accept(*this);
  }
  void Visit(const NarxLinearizingController& layer) override {
    const InputAffineNarx& m = layer.model();
    const double poly =
        static_cast<double>(m.drift_coefficients().size() + m.gain_coefficients().size()) * 2.0;
    double maps = 0.0;
    if (m.map()) maps = 2.0 * MapCost(*m.map()) + MapCost(*m.envelope());
    cost_->base += 2.0 * poly + maps + 40.0;
    layer.inner().Accept(*this);
  }
  // GenerateLayers refuses other controllers before their cost is asked for.
  void VisitOther(const Controller&) override {}

 private:
  static double MapCost(const StaticMap& f) { return 6.0 * static_cast<double>(f.size()) + 10.0; }
  // A matrix-vector product and an inner product, with their loop overheads.
  static double Gemv(double rows, double cols) { return rows * (cols + 4.0); }
  static double Dot(double n) { return n + 4.0; }

  StepCost* cost_;
};

void AddStepCost(const Controller& controller, StepCost* cost) {
  StepCostVisitor visitor(cost);
  controller.Accept(visitor);
}

// The certificate of `controller` and the QP's iteration cap in the module.
RealTimeCertificate Certify(const Controller& controller, const CodegenOptions& o) {
  using C = RealTimeCertificate;
  StepCost cost;
  AddStepCost(controller, &cost);
  C c;
  c.base_units = cost.base + 20.0;  // the guard
  c.cycles_per_instruction = o.cycles_per_instruction;
  c.utilization = o.utilization;
  int cap = 0;
  if (cost.qp != nullptr) {
    const double n = cost.qp->num_variables(), m = cost.qp->num_constraints();
    const double sides = 2.0 * (m + n);
    // The set-up (J0, the unconstrained solution, the finite sides) and one
    // constraint scan more than iterations: the scan that finds a violated
    // constraint runs before the cap is tested.
    const double scan = m * n + 15.0 * sides;
    c.qp_init_units = 3.0 * n * n + 2.0 * sides + scan + 50.0;
    c.qp_iteration_units = 6.5 * n * n + scan + 50.0;
    // The automatic cap when every side is finite (the worst case).
    const int automatic = static_cast<int>(10.0 * (n + sides) + 10.0);
    const int design =
        o.qp_max_iterations >= 0 ? o.qp_max_iterations : cost.qp->options().max_iterations;
    cap = design > 0 ? design : automatic;
    c.qp_define = design;
  }
  // Double precision runs in software on a single-precision FPU.
  const double per_unit =
      C::kInstructionsPerUnit * (o.precision == CodegenPrecision::kDouble ? C::kDoubleFactor : 1.0);
  c.instructions_per_unit = per_unit;
  auto instructions = [&](int iterations) {
    const double units = c.base_units + (iterations > 0 || cost.qp ? c.qp_init_units : 0.0) +
                         iterations * c.qp_iteration_units;
    return per_unit * units + C::kInstructionsFixed;
  };
  if (o.cpu_mhz > 0.0) {
    c.present = true;
    c.cpu_mhz = o.cpu_mhz;
    c.period = o.period > 0.0 ? o.period : controller.Ts();
    c.budget_cycles = o.utilization * c.period * o.cpu_mhz * 1e6;
    const double budget_instructions = c.budget_cycles / o.cycles_per_instruction;
    const double fixed = instructions(0);
    PNEUMID_CHECK(fixed <= budget_instructions,
                  "the real-time certificate cannot be met: a step of '{}' takes up to {:.0f} "
                  "instructions ({:.0f} cycles at {} cycles per instruction) without a QP "
                  "iteration, above the budget of {:.0f} cycles ({:g} of {:g} s at {:g} MHz); "
                  "use a faster clock, a longer period or shorter horizons",
                  controller.Describe(), fixed, fixed * o.cycles_per_instruction,
                  o.cycles_per_instruction, c.budget_cycles, o.utilization, c.period, o.cpu_mhz);
    if (cost.qp != nullptr) {
      const int fits = static_cast<int>(
          std::floor((budget_instructions - fixed) / (per_unit * c.qp_iteration_units)));
      PNEUMID_CHECK(fits >= 1,
                    "the real-time certificate cannot be met: one QP iteration of '{}' takes up "
                    "to {:.0f} instructions and the rest of the step {:.0f}, above the budget of "
                    "{:.0f} cycles ({:g} of {:g} s at {:g} MHz, {} cycles per instruction); use a "
                    "faster clock, a longer period or shorter horizons",
                    controller.Describe(), per_unit * c.qp_iteration_units, fixed, c.budget_cycles,
                    o.utilization, c.period, o.cpu_mhz, o.cycles_per_instruction);
      cap = std::min(cap, fits);
      c.qp_define = cap;
    }
  }
  c.qp_max_iterations = cap;
  c.max_instructions = instructions(cap);
  c.max_cycles = c.max_instructions * o.cycles_per_instruction;
  if (c.present) c.max_time = c.max_cycles / (o.cpu_mhz * 1e6);
  return c;
}

// The controller's code: a linear controller, or a layer (input map, output
// map, NARX linearization, sigma-delta modulator) around its inner
// controller's code, one visit per layer.
class LayerGenerator final : public ControllerVisitor {
 public:
  LayerGenerator(Module& module, int depth, CodegenResult* result)
      : module_(module), depth_(depth), result_(result) {}

  void Visit(const PidController& pid) override {
    result_->type = ControllerType::kPid;
    GeneratePid(pid, module_);
  }
  void Visit(const DmcController& dmc) override {
    result_->type = ControllerType::kDmc;
    result_->constrained = dmc.options().constrained;
    GenerateDmc(dmc, module_);
  }
  void Visit(const GpcController& gpc) override {
    result_->type = ControllerType::kGpc;
    GenerateGpc(gpc, module_);
  }
  void Visit(const MpcController& mpc) override {
    result_->type = ControllerType::kMpc;
    result_->constrained = mpc.constrained();
    GenerateMpc(mpc, module_);
  }
  void Visit(const InverseMapController& layer) override {
    const std::string stem = Inner(layer.inner());
    GenerateInverseMap(layer, module_, stem);
    result_->layers.insert(result_->layers.begin(), "input-map");
  }
  void Visit(const ModulatedController& layer) override {
    const std::string stem = Inner(layer.inner());
    GenerateModulator(layer, module_, stem);
    result_->layers.insert(result_->layers.begin(), "sigma-delta");
  }
  void Visit(const OutputMapController& layer) override {
    const std::string stem = Inner(layer.inner());
    GenerateOutputMap(layer, module_, stem);
    result_->layers.insert(result_->layers.begin(), "output-map");
  }
  void Visit(const NarxLinearizingController& layer) override {
    const std::string stem = Inner(layer.inner());
    GenerateNarxLinearization(layer, module_, stem);
    result_->layers.insert(result_->layers.begin(), "narx-linearization");
  }
  void VisitOther(const Controller& controller) override {
    PNEUMID_CHECK(false,
                  "code generation supports the dmc, gpc, pid and mpc controllers, alone or "
                  "behind an input map, an output map, a NARX linearization or a sigma-delta "
                  "modulator, not '{}'",
                  controller.Describe());
  }

 private:
  // Generates the inner controller one level deeper and hides its entry
  // points under this layer's stem, which it returns.
  std::string Inner(const Controller& inner) {
    LayerGenerator deeper(module_, depth_ + 1, result_);
    inner.Accept(deeper);
    const std::string stem = fmt::format("l{}_", depth_);
    HideEntryPoints(module_, stem);
    return stem;
  }

  Module& module_;
  int depth_;
  CodegenResult* result_;
};

void GenerateLayers(const Controller& controller, Module& m, int depth, CodegenResult* result) {
  LayerGenerator generator(m, depth, result);
  controller.Accept(generator);
}

// PFX_name -> prefix_name, and PFX_MACRO -> PREFIX_MACRO for the macros.
std::string WithPrefix(const std::string& text, const std::string& prefix,
                       const std::set<std::string>& macros) {
  std::string out;
  std::size_t pos = 0;
  for (std::size_t at; (at = text.find("PFX_", pos)) != std::string::npos;) {
    out.append(text, pos, at - pos);
    std::size_t end = at + 4;
    while (end < text.size() &&
           (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_'))
      ++end;
    const std::string name = text.substr(at + 4, end - at - 4);
    out += (macros.count(name) ? internal::Upper(prefix) : prefix) + "_" + name;
    pos = end;
  }
  out.append(text, pos, std::string::npos);
  return out;
}

std::string CertificateText(const RealTimeCertificate& c, const std::string& upper) {
  std::string text = fmt::format(
      "\nWorst-case work of one step (pneumid's operation count, bounded by "
      "measurements on a Cortex-M4F): {:.0f} instructions",
      c.max_instructions);
  if (c.qp_max_iterations > 0)
    text += fmt::format(" with the QP capped at {} iterations (`{}_QP_MAX_ITERATIONS`)",
                        c.qp_max_iterations, upper);
  if (c.present)
    text += fmt::format(
        "; at {:g} MHz and {:g} cycles per instruction, {:.0f} cycles = {:.3g} ms, within the "
        "budget of {:.0f} cycles ({:g} of the {:g} ms period)",
        c.cpu_mhz, c.cycles_per_instruction, c.max_cycles, 1e3 * c.max_time, c.budget_cycles,
        c.utilization, 1e3 * c.period);
  return text + ".\n";
}

// The struct texts of a module: the QP's (empty without a QP) and the
// state's body, with the state's size.
struct ModuleStructs {
  std::string qp_struct;
  std::string state_body;
  std::size_t state_bytes = 0;
};

ModuleStructs MakeModuleStructs(const Module& m) {
  ModuleStructs structs;
  std::size_t qp_bytes = 0;
  if (m.qp_solver_) {
    structs.qp_struct =
        "typedef struct {\n" + m.StructText(m.qp_, "", 0, &qp_bytes) + "} PFX_qp;\n\n";
  }
  structs.state_body = m.StructText(
      m.state_, m.qp_solver_ ? "  PFX_qp qp; /* QP solver data and work arrays */\n" : "", qp_bytes,
      &structs.state_bytes);
  return structs;
}

// The header PFX.h (before the prefix is applied).
std::string HeaderText(const Module& m, const CodegenResult& result, double Ts,
                       const ModuleStructs& structs) {
  const std::string& name = result.prefix;
  const std::string guard = internal::Upper(name) + "_H_";
  const std::string real = m.is_float() ? "float" : "double";
  std::string h;
  h += fmt::format(
      "/* {0}.h: {1}\n * Generated by pneumid codegen ({2} precision). C99, no dynamic memory;\n"
      " * all state in {0}_state, which the caller owns (re-entrant).\n */\n",
      name, result.description, real);
  h += "#ifndef " + guard + "\n#define " + guard +
       "\n\n#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n";
  h += "typedef " + real + " PFX_real;\n\n";
  h += fmt::format("#define PFX_TS {} /* sample time, s */\n", m.Literal(Ts));
  h += fmt::format("#define PFX_STATE_BYTES {} /* sizeof(PFX_state) with 4-byte int */\n",
                   result.ram_bytes);
  h += "\n/* Fault of the last step (PFX_state.fault; PFX_state.faults counts them). */\n"
       "#define PFX_FAULT_NONE 0\n#define PFX_FAULT_MEASUREMENT_NOT_FINITE 1\n"
       "#define PFX_FAULT_MEASUREMENT_OUT_OF_RANGE 2\n#define PFX_FAULT_SETPOINT_NOT_FINITE 3\n"
       "#define PFX_FAULT_OUTPUT_NOT_FINITE 4\n";
  if (m.qp_solver_) {
    h += "\n/* QP status (PFX_state.qp.status). */\n#define PFX_QP_SOLVED 0\n"
         "#define PFX_QP_INFEASIBLE 1\n#define PFX_QP_MAX_ITERATIONS_REACHED 2\n";
  }
  h += "\n" + structs.qp_struct + "typedef struct {\n" + structs.state_body + "} PFX_state;\n\n";
  h += R"C(/* Back to rest at u = 0, y = 0: PFX_reset(s, 0, 0). */
void PFX_init(PFX_state* s);
/* Back to rest at an operating point: input u0 applied long enough for the
   output to settle at y0. */
void PFX_reset(PFX_state* s, PFX_real u0, PFX_real y0);
/* One control step: set-point and measured output at the current sample;
   returns the input to hold over the next period (within the limits). A NaN
   or infinite measurement or set-point, or a measurement outside
   [PFX_Y_VALID_MIN, PFX_Y_VALID_MAX], is a fault: the state is not updated,
   the last valid input (or PFX_SAFE_INPUT, when defined) is returned, and
   s->fault and s->faults say so; the next valid sample resumes control. */
PFX_real PFX_step(PFX_state* s, PFX_real setpoint, PFX_real measurement);
/* The input actually applied after the last step, when a later layer changed
   it (actuator saturation): the controller takes it as its own. */
void PFX_applied(PFX_state* s, PFX_real u);

#ifdef __cplusplus
}
#endif

#endif
)C";
  return h;
}

// The source PFX.c (before the prefix is applied): the common macros, the
// module's constants, the kernels it calls and its code.
std::string SourceText(const Module& m, const CodegenResult& result) {
  const std::string& name = result.prefix;
  const bool is_float = m.is_float();
  const std::string real = is_float ? "float" : "double";
  std::string c;
  c += fmt::format("/* {0}.c: {1}\n * Generated by pneumid codegen ({2} precision). */\n", name,
                   result.description, real);
  c += fmt::format("#include \"{}.h\"\n\n#include <math.h>\n#include <string.h>\n\n", name);
  c += fmt::format("#define PFX_ZERO {}\n#define PFX_ONE {}\n#define PFX_THOUSAND {}\n",
                   m.Literal(0.0), m.Literal(1.0), m.Literal(1e3));
  c += "#define PFX_INF ((PFX_real)INFINITY)\n";
  c += fmt::format("#define PFX_EPSILON {}\n",
                   is_float ? m.Literal(std::numeric_limits<float>::epsilon())
                            : m.Literal(std::numeric_limits<double>::epsilon()));
  c += is_float ? "#define PFX_FABS fabsf\n#define PFX_HYPOT hypotf\n"
                : "#define PFX_FABS fabs\n#define PFX_HYPOT hypot\n";
  c += "#define PFX_ISFINITE(x) isfinite(x)\n\n";
  c += m.constants_ + "\n";
  if (m.dot_) c += std::string(internal::kCDot).substr(1) + "\n";
  if (m.dot_strided_) c += std::string(internal::kCDotStrided).substr(1) + "\n";
  if (m.gemv_col_) c += std::string(internal::kCGemvCol).substr(1) + "\n";
  if (m.qp_solver_) {
    c += std::string(internal::kCGemvRow).substr(1) + "\n";
    c += std::string(internal::kCTriangular).substr(1) + "\n";
    c += std::string(internal::kCQp).substr(1) + "\n";
  }
  c += m.code_;
  c += "\nvoid PFX_init(PFX_state* s) { PFX_reset(s, PFX_ZERO, PFX_ZERO); }\n";
  return c;
}

// README.md: the interface, the sizes and the certificate.
std::string ReadmeText(const CodegenResult& result, double Ts) {
  const std::string& name = result.prefix;
  const std::string real = result.precision == CodegenPrecision::kFloat ? "float" : "double";
  return fmt::format(
      R"(# {0}: generated controller

{1}, generated by `pneumid codegen` in {2} precision.

Files: `{0}.h` (interface), `{0}.c` (implementation). C99; no dynamic memory,
no library beyond `<math.h>` and `<string.h>` (link with `-lm`). All state is
in `{0}_state`, which the caller owns: the code is re-entrant, and several
controllers can run side by side.

```c
#include "{0}.h"

static {0}_state ctrl;          /* {3} bytes of RAM */

void control_init(void) {{ {0}_init(&ctrl); }}   /* or {0}_reset(&ctrl, u0, y0) */

/* Every {4} s: */
{0}_real control_step({0}_real setpoint, {0}_real y) {{
  {0}_real u = {0}_step(&ctrl, setpoint, y);
  /* If the actuator applies another value (saturation): {0}_applied(&ctrl, u_applied); */
  return u;
}}
```

| function | what |
|---|---|
| `{0}_init(s)` | reset at rest, u = 0, y = 0 |
| `{0}_reset(s, u0, y0)` | reset at an operating point: u0 applied long enough for y to settle at y0 |
| `{0}_step(s, r, y)` | one sample: set-point r, measurement y -> input u within the limits |
| `{0}_applied(s, u)` | the input actually applied (anti-windup), when it differs from the returned one |

Sample time: `{7}_TS` = {4} s. State: `sizeof({0}_state)` = `{7}_STATE_BYTES` = {3} bytes;
constant tables: {5} bytes (the code adds to the flash: measure it with
`arm-none-eabi-size` of the compiled `{0}.o`, text + data).

Bad measurements: a NaN or infinite measurement or set-point, or a measurement
outside `[{7}_Y_VALID_MIN, {7}_Y_VALID_MAX]` (compile with `-D` to set them on
the bench), is a fault: the state is not updated, `{0}_step` returns the last
valid input (or `{7}_SAFE_INPUT` when it is defined, e.g. `-D{7}_SAFE_INPUT=0.0`),
`s->fault` holds the `{7}_FAULT_*` code and `s->faults` counts the faulty
samples since the last reset; the next valid sample resumes control.
{6}{8}
The arithmetic follows pneumid's library controller step by step (same
formulas, same order of the sums), so that the double-precision module
reproduces the library's inputs to rounding.
)",
      name, result.description, real, result.ram_bytes, Ts, result.const_bytes,
      result.constrained
          ? fmt::format(
                "\nConstrained: every step may solve a dense QP (Goldfarb-Idnani dual active "
                "set, warm-started) with an iteration cap; `s->qp.status` is `{1}_QP_SOLVED`, "
                "`{1}_QP_INFEASIBLE` or `{1}_QP_MAX_ITERATIONS_REACHED`, `s->qp.iterations` the "
                "work done; a step whose QP fails applies the clipped unconstrained move and "
                "counts it in `s->qp_failures` (reset by `{0}_reset`).\n",
                name, internal::Upper(name))
          : std::string(),
      internal::Upper(name), CertificateText(result.certificate, internal::Upper(name)));
}

}  // namespace

std::string ToString(CodegenPrecision v) { return std::string(EnumToString(kPrecisionNames, v)); }

CodegenPrecision CodegenPrecisionFromString(const std::string& name) {
  return EnumFromString(kPrecisionNames, name, "precision");
}

bool CodegenOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!(cpu_mhz >= 0.0) || !std::isfinite(cpu_mhz))
    return fail(fmt::format("the clock must be >= 0 MHz (0: no certificate), got {}", cpu_mhz));
  if (!(period >= 0.0) || !std::isfinite(period))
    return fail(fmt::format("the period must be >= 0 s (0: the controller's Ts), got {}", period));
  if (!(utilization > 0.0 && utilization <= 1.0))
    return fail(fmt::format("the utilization must be in (0, 1], got {}", utilization));
  if (!(cycles_per_instruction >= 1.0) || !std::isfinite(cycles_per_instruction))
    return fail(fmt::format("cycles per instruction must be >= 1, got {}", cycles_per_instruction));
  if (qp_max_iterations < -1)
    return fail(
        fmt::format("qp_max_iterations must be -1 (the design's), 0 (automatic) or "
                    "positive, got {}",
                    qp_max_iterations));
  if (prefix.empty() || prefix.size() > 32)
    return fail(fmt::format("the prefix must have 1 to 32 characters, got {}", prefix.size()));
  if (std::isdigit(static_cast<unsigned char>(prefix[0])))
    return fail(fmt::format("the prefix '{}' must not start with a digit", Excerpt(prefix)));
  for (char ch : prefix) {
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'))
      return fail(fmt::format(
          "the prefix '{}' is not a C identifier (letters, digits and '_' only)", Excerpt(prefix)));
  }
  return true;
}

nlohmann::ordered_json CodegenResult::ToJson() const {
  nlohmann::ordered_json j;
  j["prefix"] = prefix;
  j["controller"] = pneumid::ToString(type);
  j["description"] = description;
  j["precision"] = ToString(precision);
  j["constrained"] = constrained;
  j["ram_bytes"] = ram_bytes;
  j["const_bytes"] = const_bytes;
  j["layers"] = layers;
  const RealTimeCertificate& c = certificate;
  nlohmann::ordered_json cj;
  cj["qp_max_iterations"] = c.qp_max_iterations;
  cj["max_instructions_per_step"] = std::round(c.max_instructions);
  cj["instructions_per_unit"] = c.instructions_per_unit;
  cj["units"] = {
      {"base", c.base_units}, {"qp_init", c.qp_init_units}, {"qp_iteration", c.qp_iteration_units}};
  if (c.present) {
    cj["cpu_mhz"] = c.cpu_mhz;
    cj["period"] = c.period;
    cj["utilization"] = c.utilization;
    cj["cycles_per_instruction"] = c.cycles_per_instruction;
    cj["max_cycles_per_step"] = std::round(c.max_cycles);
    cj["budget_cycles"] = std::round(c.budget_cycles);
    cj["max_time"] = c.max_time;
  }
  j["certificate"] = cj;
  j["files"] = {prefix + ".h", prefix + ".c", "README.md"};
  return j;
}

CodegenResult GenerateC(const Controller& controller, const CodegenOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid code generation options: {}", error);
  Module m(options);
  CodegenResult result;
  result.prefix = options.prefix;
  result.precision = options.precision;
  result.description = controller.Describe();
  result.certificate = Certify(controller, options);
  m.qp_max_iterations_ = result.certificate.qp_define;
  GenerateLayers(controller, m, 1, &result);
  HideEntryPoints(m, "core_");
  GenerateGuard(controller, m);

  const ModuleStructs structs = MakeModuleStructs(m);
  result.ram_bytes = structs.state_bytes;
  result.const_bytes = m.const_bytes_;
  PNEUMID_CHECK(options.max_ram_bytes == 0 || result.ram_bytes <= options.max_ram_bytes,
                "the {} controller's state needs {} bytes of RAM in {} precision, above the "
                "budget of {} bytes ({}: {}); reduce the horizons, or try --precision float",
                pneumid::ToString(result.type), result.ram_bytes, ToString(options.precision),
                options.max_ram_bytes, result.description, RamHint(result.type));

  // The step uses PFX_ISFINITE only in some controllers; keep every macro used.
  result.header =
      WithPrefix(HeaderText(m, result, controller.Ts(), structs), options.prefix, m.macros_);
  result.source = WithPrefix(SourceText(m, result), options.prefix, m.macros_);
  result.readme = ReadmeText(result, controller.Ts());
  return result;
}

std::vector<std::string> WriteCodegenFiles(const CodegenResult& result,
                                           const std::string& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec)
    throw DataError(fmt::format("{}: cannot create the directory: {}", directory, ec.message()));
  const std::filesystem::path dir(directory);
  std::vector<std::string> paths;
  const std::pair<std::string, const std::string*> files[] = {
      {result.prefix + ".h", &result.header},
      {result.prefix + ".c", &result.source},
      {"README.md", &result.readme},
  };
  for (const auto& [file, text] : files) {
    if (text->empty()) continue;
    const std::string path = (dir / file).string();
    std::ofstream out(path, std::ios::binary);
    out << *text;
    out.close();
    if (!out) throw DataError(fmt::format("{}: cannot write", path));
    paths.push_back(path);
  }
  return paths;
}

}  // namespace pneumid
