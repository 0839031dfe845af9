// Builds a controller (DMC, GPC or PID) from a model, a tuning rule and
// limits: the one place where the command line, the bindings and the
// real-time loop turn settings into a Controller.
//
//   dmc  P, M, lambda from the tuning rule (tuning.hpp); QDMC when constrained
//   gpc  N1 = 1, N2 = P, Nu = M, lambda from the tuning rule; T filter "1",
//        "A" (= the model's denominator, DMC's disturbance model) or
//        coefficients "1 -0.8" (ascending powers of q^-1)
//   pid  gains by SIMC or IMC from the model's FOPDT description (tuning.hpp,
//        FopdtFromModel), tau_c <= 0 = the rule's default
#pragma once

#include <limits>
#include <memory>
#include <string>

#include "pneumid/control/controller.hpp"
#include "pneumid/control/pid.hpp"
#include "pneumid/control/tuning.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

struct ControllerSpec {
  ControllerType type = ControllerType::kDmc;
  TuningOptions tuning;  ///< P, M, lambda (dmc, gpc)
  InputLimits limits;
  bool constrained = false;                                 ///< dmc: QDMC with the QP solver
  double y_min = -std::numeric_limits<double>::infinity();  ///< soft output bounds (QDMC)
  double y_max = std::numeric_limits<double>::infinity();
  std::string t_filter = "1";  ///< gpc
  PidTuningRule pid_rule = PidTuningRule::kSimc;
  double tau_c = 0.0;  ///< pid closed-loop time constant (s); <= 0 = rule default
};

struct BuiltController {
  std::unique_ptr<Controller> controller;
  TuningResult tuning;    ///< horizons and lambda (dmc, gpc)
  PidGains pid_gains;     ///< (pid)
  FopdtParameters fopdt;  ///< the FOPDT the PID was tuned from (pid)
};

/// @throws InvalidArgument for invalid settings (messages name the setting).
BuiltController MakeController(const TransferFunction& model, double Ts,
                               const ControllerSpec& spec);

}  // namespace pneumid
