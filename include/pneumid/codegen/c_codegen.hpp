// Embedded C code generation: a designed controller (DMC/QDMC, GPC, PID, MPC)
// written as a self-contained C99 module for a microcontroller.
//
// The generated NAME.h / NAME.c use fixed-size static arrays, no dynamic
// allocation and no library beyond <math.h> and <string.h>; all state lives
// in a struct the caller owns (re-entrant):
//
//   NAME_state s;
//   NAME_init(&s);                      // at rest: NAME_reset(&s, 0, 0)
//   NAME_reset(&s, u0, y0);             // Controller::Reset
//   u = NAME_step(&s, setpoint, y);     // Controller::Update
//   NAME_applied(&s, u_applied);        // Controller::Applied (anti-windup)
//
// What the module computes is the library controller's Update() with the
// matrices and gains the library designed (read through the controllers'
// accessors, never re-derived), in the library's order of operations:
//  * PID: the discrete law of pid.hpp with the constants Kc Ts / Ti,
//    Td / (Td + N Ts), Kc Td N / (Td + N Ts), Ts / Tt folded in as the
//    library's expressions evaluate them;
//  * DMC: the free response from the stored prediction yhat_0..yhat_N and
//    the move du = (sum k') w - k' f (dmc.hpp); QDMC: the QP below;
//  * GPC: the filtered histories and the free response F y_f + Gamma Du_f
//    (gpc.hpp);
//  * MPC: the Kalman correction, the target, the unconstrained moves
//    Fz z + Fu u + Fr r + Fs u_s and, when a bound is violated, the QP
//    (mpc.hpp).
// Sums are evaluated in the order of the library's Eigen 3.4 kernels with
// SSE2 (inner products in two lanes of two-element packets, column-major
// matrix-vector products row by row), so that in double precision the
// generated code reproduces the library's inputs to rounding (agreement to
// about 1e-13 relative over long closed-loop runs; tests/codegen).
//
// The constrained controllers carry a C version of QpSolver (qp_solver.hpp,
// Goldfarb-Idnani with warm start): the same constraint ordering, violation
// test, step lengths, Givens updates and iteration cap; a step whose QP does
// not return "solved" applies the clipped unconstrained move as the library
// does, and counts it in qp_failures.
//
// Layers (inverse_map_controller.hpp, narx_linearizing_controller.hpp): the
// input map's inverse in front of the inner controller's input (Hammerstein),
// the output map's inverse on its set-point and measurement (Wiener), the
// NARX linearization; piecewise-linear maps with StaticMap's segment search
// and expressions, the NARX polynomials by Horner's rule as the library.
// In front of everything, the MeasurementGuard (controller.hpp): a faulty
// sample (NaN/Inf, out of [PFX_Y_VALID_MIN, PFX_Y_VALID_MAX]) leaves the
// state untouched and returns the held or safe input.
//
// Single precision: the tables are rounded to float and so is the
// arithmetic. The MPC computes its moves (and the QP's linear term) from the
// deviation of the state and input from the target's steady state, and the
// GPC its free response from the deviations of the filtered output from its
// latest value: the dropped terms cancel exactly, and without them the
// rounding of large cancelling terms biases the moves and the input's
// integrator accumulates the bias. The QP's feasibility tolerance is
// max(tolerance, 1e-4) (units of the moves) and its degeneracy threshold uses
// the float epsilon. See docs/codegen.md for the measured agreement.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "pneumid/control/controller.hpp"

namespace pneumid {

/// Floating-point type of the generated tables and arithmetic: C `double` or `float`
/// (single precision for an FPU such as the Cortex-M4F's).
enum class CodegenPrecision { kDouble, kFloat };
/// "double", "float".
std::string ToString(CodegenPrecision precision);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
CodegenPrecision CodegenPrecisionFromString(const std::string& name);

/// Options of GenerateC: precision, names, RAM budget, QP cap and the target's timing.
struct CodegenOptions {
  /// Type of the tables and the arithmetic (double reproduces the library to rounding).
  CodegenPrecision precision = CodegenPrecision::kDouble;
  /// Prefix of every exported name and of the file names: a C identifier of
  /// at most 32 characters (letters, digits, '_', not starting with a digit).
  std::string prefix = "pneumid_ctrl";
  /// RAM budget in bytes for the controller's state struct (0 = none).
  std::size_t max_ram_bytes = 0;
  /// Iteration cap of the constrained controllers' QP (PFX_QP_MAX_ITERATIONS,
  /// which -D can override at compile time): -1 = the design's (QpOptions),
  /// 0 = 10 (n + finite sides) + 10.
  int qp_max_iterations = -1;
  /// Real-time certificate (RealTimeCertificate): the target's clock in MHz
  /// (0 = no certificate) and the control period in s (0 = the controller's
  /// Ts). With a clock, the QP's iteration cap is the largest whose worst
  /// case fits in `utilization` of the period (and at most the cap above).
  double cpu_mhz = 0.0;
  double period = 0.0;  ///< control period in s for the certificate (0 = the controller's Ts)
  /// Fraction of the period the controller may take (the rest is the ADC,
  /// the PWM, communication and interrupts).
  double utilization = 0.5;
  /// Cycles per executed instruction assumed on the target: a Cortex-M4F
  /// runs most instructions in one cycle; loads, multi-cycle FPU
  /// divisions/square roots, branches and flash wait states raise the mean.
  double cycles_per_instruction = 1.5;
  /// True when cpu_mhz, period >= 0, utilization in (0, 1], cycles_per_instruction >= 1,
  /// qp_max_iterations >= -1 and prefix is a C identifier of 1..32 characters; otherwise
  /// false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// The worst-case work of one step of a generated module, from a count of
/// its operations (multiply-adds, comparisons, map segments) at the largest
/// QP work the iteration cap allows:
///   instructions <= kInstructionsPerUnit * (base + init + cap * per_iteration)
///                   + kInstructionsFixed
/// (kInstructionsPerUnit times kDoubleFactor in double precision),
/// with base the step outside the QP, init the QP's set-up and one constraint
/// scan, per_iteration the dual active-set iteration's work (directions
/// 2.5 n^2, Givens updates 4 n^2, constraint scan m n + 15 (2 m + 2 n), for n
/// variables and m rows).
/// The constants are upper bounds of the instructions per unit measured on a
/// Cortex-M4F under QEMU (-icount, gcc -O2, examples/cortex-m4), where the
/// test tests/target/cortex_m4_test.sh checks that every scenario's measured
/// worst step stays below the certificate.
struct RealTimeCertificate {
  /// Instructions per counted operation unit in single precision (measured upper bound).
  static constexpr double kInstructionsPerUnit = 6.0;
  /// Constant allowance of instructions per step, added to the scaled units.
  static constexpr double kInstructionsFixed = 400.0;
  /// Double precision in software on the M4F's single-precision FPU (the
  /// paper's DMC: 17 times the instructions of float).
  static constexpr double kDoubleFactor = 20.0;
  bool present = false;      ///< a clock was given
  double cpu_mhz = 0.0;      ///< target clock in MHz (CodegenOptions::cpu_mhz; 0 without one)
  double period = 0.0;       ///< s
  double utilization = 0.0;  ///< fraction of the period granted to the step
  double cycles_per_instruction = 0.0;  ///< assumed mean cycles per instruction
  /// The largest number of QP iterations a step can run (0: no QP).
  int qp_max_iterations = 0;
  /// PFX_QP_MAX_ITERATIONS in the module: the design's cap (0: automatic, at
  /// most qp_max_iterations) without a clock, qp_max_iterations with one.
  int qp_define = 0;
  double base_units = 0.0,       ///< operation units of the step outside the QP (with the guard)
      qp_init_units = 0.0,       ///< units of the QP's set-up and first scan (0: no QP)
      qp_iteration_units = 0.0;  ///< units of one dual active-set iteration (0: no QP)
  double instructions_per_unit = 0.0;  ///< kInstructionsPerUnit, times kDoubleFactor in double
  double max_instructions = 0.0;       ///< per step, at the cap
  double max_cycles = 0.0;             ///< max_instructions * cycles_per_instruction
  double budget_cycles = 0.0;          ///< utilization * period * clock
  double max_time = 0.0;               ///< s, max_cycles / clock
};

/// The generated C module (texts of the files) and its resource figures.
struct CodegenResult {
  ControllerType type = ControllerType::kDmc;  ///< the linear controller inside the layers
  CodegenPrecision precision = CodegenPrecision::kDouble;  ///< CodegenOptions::precision
  std::string prefix;  ///< CodegenOptions::prefix: NAME of the files and exported names
  std::string header;  ///< NAME.h
  std::string source;  ///< NAME.c
  std::string readme;  ///< README.md of the interface
  /// sizeof(NAME_state) on a target with 4-byte int and naturally aligned
  /// float/double (x86-64, Cortex-M EABI): the RAM the caller provides.
  std::size_t ram_bytes = 0;
  /// Bytes of the constant tables (flash; code not included).
  std::size_t const_bytes = 0;
  bool constrained = false;  ///< the module contains the QP solver
  /// The worst-case work per step (always computed; `present` with a clock).
  RealTimeCertificate certificate;
  /// Layers around the linear controller, outermost first: "input-map"
  /// (Hammerstein), "output-map" (Wiener), "narx-linearization".
  std::vector<std::string> layers;
  std::string description;  ///< controller.Describe()
  /// {prefix, controller, description, precision, constrained, ram_bytes,
  /// const_bytes, layers, certificate, files}.
  nlohmann::ordered_json ToJson() const;
};

/// Generates the C module of `controller` (a PidController, DmcController,
/// GpcController or MpcController, alone or behind an InverseMapController,
/// OutputMapController or NarxLinearizingController, as the controller
/// factory builds them for Hammerstein, Wiener and input-affine NARX models),
/// with the controller's MeasurementGuard in front.
/// @throws InvalidArgument for invalid options, another Controller type, a
/// non-finite design constant, a state above options.max_ram_bytes (the
/// message gives the size and what it grows with), or a certificate that
/// cannot be met: the step without a QP iteration, or with fewer than one,
/// above the budget (the message gives both figures).
CodegenResult GenerateC(const Controller& controller, const CodegenOptions& options);

/// Writes NAME.h, NAME.c and README.md of `result` into `directory`
/// (created if missing), skipping an empty text; returns the paths written.
/// @throws DataError when a file cannot be written.
std::vector<std::string> WriteCodegenFiles(const CodegenResult& result,
                                           const std::string& directory);

}  // namespace pneumid
