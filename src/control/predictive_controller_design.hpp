// Private helper of the controller factory (controller_factory.cpp) and the
// auto-tuner (auto_tuning.cpp): the one construction of a dmc, gpc or mpc
// controller from a sampled model and the settings of a ControllerSpec. The
// factory builds every such controller with it, after unwrapping the input
// map, output map and NARX layers and resolving the rule auto; the
// auto-tuner builds each candidate of its lambda search with it. So the
// controllers the auto-tuner evaluates are the ones MakeController builds
// for the same P, M and lambda, designed on the same sampled model
// (PredictionModel, which also holds the state space of the mpc), and the
// factory's rule auto deploys the tuned settings with the same options: the
// constrained form of the dmc (AutoTunedDmcIsConstrained) and the mpc's
// disturbance model and noise variances.
#pragma once

#include "pneumid/control/controller_factory.hpp"
#include "pneumid/control/prediction_model.hpp"

namespace pneumid::internal {

// The dmc, gpc or mpc controller of `spec` on `model`: P, M and lambda from
// Tune(model, spec.tuning), then the type's options from spec (limits;
// dmc: constrained and the soft output bounds; gpc: the T filter; mpc: the
// soft output bounds, the disturbance model and the Kalman noises, NaN = the
// defaults). `spec` must not ask for auto_tune nor carry an input map, output
// map or NARX model; the result has no outer layers (measurement guard,
// modulator). BuiltController::type, pid_rule and tuning are filled in.
// @throws InvalidArgument for a pid or auto_tune spec, and for settings the
// tuning or the controller rejects (messages name the setting).
BuiltController MakePredictiveController(const PredictionModel& model, const ControllerSpec& spec);

// Whether a dmc tuned by the rule auto is a QDMC: when any limit of `limits`
// (u_min, u_max, du_max) is finite, or when `constrained` asks for it. The
// auto-tuner evaluates its candidates so and the factory deploys the tuned
// dmc so (a clipping dmc would not be the controller the tuner checked).
bool AutoTunedDmcIsConstrained(const InputLimits& limits, bool constrained);

}  // namespace pneumid::internal
