// A discrete linear plant for the control tests: the model sampled with a
// zero-order hold (SampledModel) run as a difference equation, with the load
// disturbance added to the output.
#pragma once

#include <string>
#include <vector>

#include "pneumid/control/dmc.hpp"
#include "pneumid/plant/plant.hpp"

namespace pneumid::testing_util {

class DifferenceEquationPlant : public Plant {
 public:
  DifferenceEquationPlant(const TransferFunction& model, double Ts)
      : g_(SampledModel(model, Ts)), Ts_(Ts) {
    Reset();
  }
  void Reset() override {
    const int d = g_.DelaySamples();
    u_.assign(g_.num().size() + d + 1, 0.0);
    y_.assign(g_.den().size() + 1, 0.0);
    t_ = 0.0;
    load_disturbance_ = 0.0;
  }
  double Measure() override { return y_[0] + load_disturbance_; }
  void Advance(double u) override {
    // shift the input history and compute the next output
    for (std::size_t i = u_.size() - 1; i > 0; --i) u_[i] = u_[i - 1];
    u_[0] = u;
    const int d = g_.DelaySamples();
    const auto& b = g_.num();
    const auto& a = g_.den();
    // y[k+1] a0 = sum_i b_i u[k+1-d-i] - sum_{i>=1} a_i y[k+1-i]; u[k+1] is not
    // applied yet, so b_0 with d = 0 would need it: the models here are
    // strictly proper (b_0 = 0 when d = 0).
    double acc = 0.0;
    for (int i = 0; i < b.size(); ++i) {
      const int lag = d + i - 1;  // u[k+1-d-i] = u_[d + i - 1]
      if (lag >= 0) acc += b(i) * u_[lag];
    }
    for (std::size_t i = y_.size() - 1; i > 0; --i) y_[i] = y_[i - 1];
    for (int i = 1; i < a.size(); ++i) acc -= a(i) * y_[i];
    y_[0] = acc / a(0);
    t_ += Ts_;
  }
  double Ts() const override { return Ts_; }
  double time() const override { return t_; }
  std::string Describe() const override { return "difference equation " + g_.ToString(); }

 private:
  TransferFunction g_;
  double Ts_;
  std::vector<double> u_, y_;  // u_[0] = u[k], y_[0] = y[k]
  double t_ = 0.0;
};

}  // namespace pneumid::testing_util
