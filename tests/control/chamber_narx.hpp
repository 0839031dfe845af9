// A known input-affine NARX model of a chamber, shared by the tests of the
// NARX linearization (control) and of its generated C (codegen).
#pragma once

#include "pneumid/models/narx_model.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid::testing_models {

// y(t) = y(t-1) + a(z) + v b(z) in z = y / 200, v = f(u) in [0, 1]:
// venting -0.03 z - 0.02 z^2, filling (0.12 - 0.05 z) v; written as the
// NARX of the normalised signals with u_offset 0.5, u_scale 0.5 (v enters
// as (v - 0.5) / 0.5), as an estimator may write it.
inline NarxModel ChamberNarx(double Ts) {
  NarxModel m;
  m.ny = m.nu = m.nk = 1;
  m.degree = 3;
  m.Ts = Ts;
  m.u_offset = 0.5;
  m.u_scale = 0.5;
  m.y_scale = 200.0;
  // theta on (v - 0.5)/0.5 = 2 v - 1: a v-term c v z^k becomes (c/2) w z^k + (c/2) z^k.
  m.terms = {{}, {0}, {0, 0}, {1}, {0, 1}};
  const double b0 = 0.12, b1 = -0.05;
  // v = (w + 1) / 2 for the normalised input w: b(z) v = b(z) / 2 + b(z) w / 2.
  m.theta = {b0 / 2, 1.0 - 0.03 + b1 / 2, -0.02, b0 / 2, b1 / 2};
  m.err.assign(m.terms.size(), 0.0);
  return m;
}

// The valve map: dead band to 10 %, a small dip in it (as fitted maps have).
inline StaticMap ChamberValve() { return StaticMap({0, 5, 10, 50, 100}, {0, -0.01, 0, 0.6, 1.0}); }

}  // namespace pneumid::testing_models
