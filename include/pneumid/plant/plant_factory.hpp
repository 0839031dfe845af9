// Plants by name, for every command that takes `--plant`:
//
//   ipa                         the IPA physics simulator, force mode (rod fixed), output N
//   ipa-position                the position rig (moving piston, four valves, signed
//                               command -100..100 %), output m
//   ipa:config=FILE.toml[,mode=force|position][,pwm=switching|averaged]
//                               parameters from a TOML file (config/ipa_default.toml)
//   anything ParseModelSpec accepts (pneumid/models/model_file.hpp): arx-paper,
//   arx-paper-ct, fopdt-paper, fopdt:K=1.6,tau=0.245,theta=0.001, sopdt:..., tf:...,
//   a model JSON file written by pneumid   -> LinearPlant
// Input of the IPA: PWM duty in percent; of a linear model: its own input unit.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "pneumid/data/dataset.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/plant.hpp"

namespace pneumid {

/// Options of MakePlant common to every plant kind: seed, noise, IPA configuration.
struct PlantOptions {
  /// Seed of every noise generator of the plant (runs are reproducible).
  std::uint64_t seed = 1;
  /// Measurement noise standard deviation in output units (N or m for the IPA,
  /// the model's output unit otherwise). Unset: the plant's own default (0 for
  /// linear models; for the IPA the sensor noise of its parameters). Set for
  /// the IPA, it replaces the pressure (force mode) or position sensor noise.
  std::optional<double> noise_sigma;
  /// IPA parameter file (TOML); empty: built-in defaults. A config= in the spec wins.
  std::string config_path;
  /// Overrides the IPA's PWM simulation mode when set (spec pwm= wins).
  std::optional<PwmMode> pwm_mode;

  /// True unless noise_sigma is set and not a finite value >= 0; otherwise false with
  /// the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Builds the plant named by `spec` (see above) sampled at Ts seconds.
/// @throws InvalidArgument for an unknown spec, bad options or Ts <= 0;
///         DataError for an unreadable or invalid model/config file.
std::unique_ptr<Plant> MakePlant(const std::string& spec, double Ts,
                                 const PlantOptions& options = {});

/// Input and output channel (name "u"/"y" and unit) of a plant made by MakePlant:
/// {"u","%"} and {"y","N"} or {"y","m"} for the IPA, unit-less otherwise
/// (PlantActuator(plant).input and .output, plant/actuator.hpp).
Channel PlantInputChannel(const Plant& plant);
Channel PlantOutputChannel(const Plant& plant);  ///< output channel, see PlantInputChannel

/// Help text for the CLI's --plant option.
std::string PlantSpecHelp();

}  // namespace pneumid
