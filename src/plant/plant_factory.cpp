// Plants by name (see include/pneumid/plant/plant_factory.hpp).
#include "pneumid/plant/plant_factory.hpp"

#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/mapped_plant.hpp"

namespace pneumid {

bool PlantOptions::IsValid(std::string* error) const {
  if (noise_sigma && !(std::isfinite(*noise_sigma) && *noise_sigma >= 0.0)) {
    if (error) *error = fmt::format("noise sigma must be >= 0, got {}", *noise_sigma);
    return false;
  }
  return true;
}

namespace {

std::unique_ptr<Plant> MakeIpa(const std::string& spec, const std::string& base, double Ts,
                               const PlantOptions& options) {
  std::string config = options.config_path;
  std::optional<IpaMode> mode;
  if (base == "ipa-position") mode = IpaMode::kPosition;
  std::optional<PwmMode> pwm = options.pwm_mode;
  Spec fields("plant", spec);
  config = fields.Text("config", config);
  if (fields.Has("mode")) mode = IpaModeFromString(fields.Text("mode"));
  if (fields.Has("pwm")) pwm = PwmModeFromString(fields.Text("pwm"));
  fields.Finish();
  const IpaMode base_mode = mode.value_or(IpaMode::kForce);
  IpaParameters p =
      config.empty() ? DefaultIpaParameters(base_mode) : LoadIpaParameters(config, base_mode);
  if (mode) p.mode = *mode;
  if (pwm) p.pwm_mode = *pwm;
  if (options.noise_sigma) {
    if (p.mode == IpaMode::kForce)
      p.pressure_noise = *options.noise_sigma / p.AreaA();
    else
      p.position_noise = *options.noise_sigma;
  }
  return std::make_unique<IpaSimulator>(p, Ts, options.seed);
}

}  // namespace

std::unique_ptr<Plant> MakePlant(const std::string& spec, double Ts, const PlantOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid plant options: {}", error);
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(!spec.empty(), "empty plant spec; give ipa, ipa-position or a model ({})",
                "arx-paper, fopdt:K=..,tau=..,theta=.., MODEL.json");
  const std::string base = spec.substr(0, spec.find(':'));
  if (base == "ipa" || base == "ipa-position") return MakeIpa(spec, base, Ts, options);
  TransferFunction g;
  try {
    g = ParseModelSpec(spec);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(fmt::format(
        "unknown plant '{}': expected ipa, ipa-position, ipa:config=FILE.toml or a model ({})",
        spec, e.what()));
  }
  // A model file's maps are part of the plant: what the model predicts on
  // data (mapped_plant.hpp), not its linear part alone.
  MappedPlant::Parts parts;
  parts.input_map = ParseModelInputMap(spec);
  parts.output_map = ParseModelOutputMap(spec);
  if (parts.input_map || parts.output_map)
    return std::make_unique<MappedPlant>(g, std::move(parts), Ts,
                                         options.noise_sigma.value_or(0.0), options.seed, spec);
  return std::make_unique<LinearPlant>(g, Ts, options.noise_sigma.value_or(0.0), options.seed,
                                       spec);
}

Channel PlantInputChannel(const Plant& plant) { return PlantActuator(plant).input; }

Channel PlantOutputChannel(const Plant& plant) { return PlantActuator(plant).output; }

std::string PlantSpecHelp() {
  return R"(Plant specs:
  ipa                      IPA physics simulator, force mode (rod fixed): input PWM duty %,
                           output force N (docs/simulator.md)
  ipa-position             the position rig: moving piston, four valves, command -100..100 %, output m
  ipa:config=FILE.toml[,mode=force|position][,pwm=switching|averaged]
                           IPA with parameters from a TOML file (see config/ipa_default.toml)
  arx-paper                the paper's ARX(3,3,1) force model, Ts = 0.01 s (Eq. 5)
  arx-paper-ct, fopdt-paper, fopdt:K=1.6,tau=0.245,theta=0.001, sopdt:K=..,tau1=..,tau2=..,theta=..,
  tf:num=..,den=..[,Ts=..]  linear models (continuous ones discretized with zoh at --Ts)
  MODEL.json[#method]      a model written by pneumid (identify --json), with its input and
                           output maps, in deviations from its operating point (NARX models
                           cannot be plants)
)";
}

}  // namespace pneumid
