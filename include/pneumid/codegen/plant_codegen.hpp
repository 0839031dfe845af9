// A linear plant as an embedded C99 module, to run a generated controller in
// closed loop where there is no plant: on a development board or in an
// emulator (examples/cortex-m4).
//
// The model is a discrete SISO state space with its input delay as states
// (SampledStateSpace of mpc.hpp for a transfer function),
//   x+ = A x + B u,   y = C x + D u,
// written as NAME.h / NAME.c with the same conventions as the controllers'
// modules (c_codegen.hpp): fixed-size arrays, state in a caller-owned struct:
//
//   NAME_state p;
//   NAME_reset(&p, u0);           // at the steady state of u0: x = (I - A)^-1 B u0
//   y = NAME_output(&p, u);       // C x + D u (D = 0 for a delayed model)
//   NAME_advance(&p, u);          // x <- A x + B u
#pragma once

#include "pneumid/codegen/c_codegen.hpp"
#include "pneumid/lti/state_space.hpp"

namespace pneumid {

/// The C module of `model` (ram_bytes the state struct; type and
/// constrained are not used).
/// @throws InvalidArgument for invalid options, a continuous or non-SISO
/// model, a non-finite matrix, or I - A singular (an integrator).
CodegenResult GenerateLinearPlantC(const StateSpace& model, const CodegenOptions& options);

}  // namespace pneumid
