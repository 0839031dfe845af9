// A model file's plant: its linear part behind the model's static maps, so
// that `--plant MODEL.json#METHOD` simulates a Hammerstein, Wiener or
// Hammerstein-Wiener model as it predicts on data, not its linear part alone.
//
// With the linear part G (a LinearPlant without noise) and the optional input
// map f and output map g (StaticMap, models/static_map.hpp):
//   v_k = f(u_k) with an input map (Hammerstein, static map, HW), else u_k;
//   x   = G v,   y_k = g(x_k) with an output map (Wiener, HW), else x_k;
//   y_meas,k = y_k + load disturbance + e_k,   e_k ~ N(0, sigma^2),
// starting with G at rest (x = 0). A model without maps is the LinearPlant
// itself (plant_factory.hpp builds this plant only when the model has a
// map). A linear model's operating point is not applied: plants and
// controllers built from a model file work in the deviations from it, in
// which it was identified (docs/getting-started.md, the tanks).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "pneumid/models/static_map.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/seeded_noise.hpp"

namespace pneumid {

/// A linear plant behind static input and output maps (see above).
class MappedPlant final : public Plant {
 public:
  /// The parts of the model (see above).
  struct Parts {
    std::optional<StaticMap> input_map;   ///< f, input units -> G's input
    std::optional<StaticMap> output_map;  ///< g, G's output -> output units
  };
  /// `linear`: G at the plant's sample time; `noise_sigma`, `seed` as LinearPlant's.
  /// @throws InvalidArgument as LinearPlant, or without any map.
  MappedPlant(const TransferFunction& linear, Parts parts, double Ts, double noise_sigma = 0.0,
              std::uint64_t seed = 1, std::string name = "");

  void Reset() override;
  double Measure() override;
  void Advance(double u) override;
  double Ts() const override { return linear_.Ts(); }
  double time() const override { return linear_.time(); }
  /// "y_true" (noise-free output), "x" (the linear part's output).
  std::map<std::string, double> Extras() const override;
  std::string Describe() const override;

  /// The parts the plant runs.
  const Parts& parts() const { return parts_; }

 private:
  double Output() const;

  LinearPlant linear_;
  Parts parts_;
  SeededNoise noise_;  ///< the measurement noise, drawn per sample
  std::string name_;
};

}  // namespace pneumid
