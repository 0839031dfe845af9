// A linear plant behind static maps (see
// include/pneumid/plant/mapped_plant.hpp).
#include "pneumid/plant/mapped_plant.hpp"

#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

MappedPlant::MappedPlant(const TransferFunction& linear, Parts parts, double Ts,
                         double noise_sigma, std::uint64_t seed, std::string name)
    : linear_(linear, Ts),
      parts_(std::move(parts)),
      noise_(noise_sigma, seed),
      name_(std::move(name)) {
  PNEUMID_CHECK(parts_.input_map || parts_.output_map,
                "a mapped plant needs an input or an output map (else use LinearPlant)");
  Reset();
}

void MappedPlant::Reset() {
  linear_.Reset();
  noise_.Reset();
  load_disturbance_ = 0.0;
}

double MappedPlant::Output() const {
  const double x = linear_.output();
  return parts_.output_map ? parts_.output_map->Evaluate(x) : x;
}

double MappedPlant::Measure() { return Output() + load_disturbance_ + noise_.value(); }

void MappedPlant::Advance(double u) {
  PNEUMID_CHECK(std::isfinite(u), "plant input must be finite, got {}", u);
  linear_.Advance(parts_.input_map ? parts_.input_map->Evaluate(u) : u);
  noise_.Next();
}

std::map<std::string, double> MappedPlant::Extras() const {
  return {{"y_true", Output()}, {"x", linear_.output()}};
}

std::string MappedPlant::Describe() const {
  std::string parts;
  if (parts_.input_map) parts += ", behind its input map";
  if (parts_.output_map) parts += ", with its output map";
  return fmt::format("{}{}{}{}", name_.empty() ? "" : name_ + ": ",
                     linear_.Describe(), parts,
                     noise_.sigma() > 0.0 ? fmt::format(", output noise sigma {:g}", noise_.sigma())
                                        : std::string());
}

}  // namespace pneumid
