// IPA physics simulator (see include/pneumid/plant/ipa_simulator.hpp).
#include "pneumid/plant/ipa_simulator.hpp"

#include "pneumid/plant/actuator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <boost/numeric/odeint.hpp>

#include "ipa_valve.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {

constexpr double kRho0 = 1.185;     // kg/m^3, ISO 8778 reference atmosphere
constexpr double kT0 = 293.15;      // K
constexpr double kBar = 1e5;        // state scaling: pressures in bar
constexpr double kMm = 1e-3;        // positions in mm
constexpr double kGram = 1e-3;      // masses in g
constexpr double kMicron = 1e-6;    // LuGre bristle deflection in um
constexpr double kEventTol = 1e-9;  // s, events closer than this are simultaneous

// Position mode: a signed duty of magnitude a (0..1) keeps its valves open the
// whole PWM period T when it is full, or when its off time is shorter than the
// minimum pulse width w_min (the valves cannot close for so short a time).
bool HeldOpen(double a, double T, double w_min) {
  return a >= 1.0 || (a > 0.0 && (1.0 - a) * T < w_min);
}

}  // namespace

namespace {
constexpr EnumName<IpaMode> kIpaModeNames[] = {
    {IpaMode::kForce, "force"},
    {IpaMode::kPosition, "position"},
};
}  // namespace

std::string ToString(IpaMode v) { return std::string(EnumToString(kIpaModeNames, v)); }

IpaMode IpaModeFromString(const std::string& name) {
  return EnumFromString(kIpaModeNames, name, "IPA mode");
}

namespace {
constexpr EnumName<PwmMode> kPwmModeNames[] = {
    {PwmMode::kSwitching, "switching"},
    {PwmMode::kAveraged, "averaged"},
    {PwmMode::kSwitching, "pwm"},
    {PwmMode::kAveraged, "average"},
};
}  // namespace

std::string ToString(PwmMode v) { return std::string(EnumToString(kPwmModeNames, v)); }

PwmMode PwmModeFromString(const std::string& name) {
  return EnumFromString(kPwmModeNames, name, "PWM mode");
}

double IpaParameters::AreaA() const { return std::numbers::pi / 4.0 * bore * bore; }
double IpaParameters::AreaB() const { return std::numbers::pi / 4.0 * (bore * bore - rod * rod); }

bool IpaParameters::IsValid(std::string* error) const {
  auto fail = [&](const std::string& msg) {
    if (error) *error = msg;
    return false;
  };
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  struct Check {
    double value;
    const char* name;
    const char* unit;
  };
  for (const Check& c : {Check{bore, "cylinder.bore", "m"},
                         Check{stroke, "cylinder.stroke", "m"},
                         Check{dead_volume_a, "cylinder.dead_volume_a", "m^3"},
                         Check{dead_volume_b, "cylinder.dead_volume_b", "m^3"},
                         Check{supply_pressure, "supply.pressure", "Pa"},
                         Check{atmospheric_pressure, "supply.atmospheric_pressure", "Pa"},
                         Check{temperature, "supply.temperature", "K"},
                         Check{supply_line_conductance, "supply.line_conductance", "m^3/(s Pa)"},
                         Check{gas_constant, "gas.gas_constant", "J/(kg K)"},
                         Check{alpha_in, "gas.alpha_in", ""},
                         Check{alpha_out, "gas.alpha_out", ""},
                         Check{alpha, "gas.alpha", ""},
                         Check{inlet_conductance, "valves.inlet_conductance", "m^3/(s Pa)"},
                         Check{exhaust_conductance, "valves.exhaust_conductance", "m^3/(s Pa)"},
                         Check{pwm_frequency, "pwm.frequency", "Hz"},
                         Check{manifold_volume, "valves.manifold_volume", "m^3"},
                         Check{mass, "mechanics.mass", "kg"},
                         Check{stribeck_velocity, "mechanics.stribeck_velocity", "m/s"},
                         Check{friction_smoothing_velocity, "mechanics.smoothing_velocity", "m/s"},
                         Check{pressure_full_scale, "sensors.pressure_full_scale", "Pa"},
                         Check{adc_range, "sensors.adc_range", "V"},
                         Check{relative_tolerance, "simulation.relative_tolerance", ""},
                         Check{absolute_tolerance, "simulation.absolute_tolerance", ""}}) {
    if (!positive(c.value))
      return fail(fmt::format("{} must be positive, got {} {}", c.name, c.value, c.unit));
  }
  for (const Check& c :
       {Check{open_delay, "valves.open_delay", "s"}, Check{close_delay, "valves.close_delay", "s"},
        Check{min_pulse_width, "valves.min_pulse_width", "s"},
        Check{tube_conductance, "valves.tube_conductance", "m^3/(s Pa)"},
        Check{viscous_friction, "mechanics.viscous_friction", "N s/m"},
        Check{coulomb_friction, "mechanics.coulomb_friction", "N"},
        Check{static_friction, "mechanics.static_friction", "N"},
        Check{end_stop_stiffness, "mechanics.end_stop_stiffness", "N/m"},
        Check{end_stop_damping, "mechanics.end_stop_damping", "N s/m"},
        Check{pressure_noise, "sensors.pressure_noise", "Pa"},
        Check{pressure_filter_time_constant, "sensors.pressure_filter_time_constant", "s"},
        Check{position_noise, "sensors.position_noise", "m"}, Check{rod, "cylinder.rod", "m"},
        Check{lugre_stiffness, "mechanics.lugre_stiffness", "N/m"},
        Check{lugre_damping, "mechanics.lugre_damping", "N s/m"},
        Check{position_resolution, "sensors.position_resolution", "m"}}) {
    if (!(std::isfinite(c.value) && c.value >= 0.0))
      return fail(fmt::format("{} must be >= 0, got {} {}", c.name, c.value, c.unit));
  }
  if (!(rod < bore))
    return fail(
        fmt::format("cylinder.rod = {} m must be smaller than cylinder.bore = {} m", rod, bore));
  if (!(piston_position >= 0.0 && piston_position <= stroke))
    return fail(fmt::format("cylinder.piston_position = {} m must be within the stroke 0..{} m",
                            piston_position, stroke));
  for (const Check& c : {Check{inlet_critical_ratio, "valves.inlet_critical_ratio", ""},
                         Check{exhaust_critical_ratio, "valves.exhaust_critical_ratio", ""},
                         Check{tube_critical_ratio, "valves.tube_critical_ratio", ""},
                         Check{supply_line_critical_ratio, "supply.line_critical_ratio", ""}}) {
    if (!(c.value >= 0.0 && c.value < laminar_ratio))
      return fail(fmt::format("{} must be in [0, valves.laminar_ratio = {}), got {}", c.name,
                              laminar_ratio, c.value));
  }
  if (!(laminar_ratio > 0.0 && laminar_ratio < 1.0))
    return fail(fmt::format("valves.laminar_ratio must be in (0, 1), got {}", laminar_ratio));
  if (!std::isfinite(force_offset))
    return fail(fmt::format("sensors.force_offset must be finite, got {}", force_offset));
  if (adc_bits < 0 || adc_bits > 32)
    return fail(
        fmt::format("sensors.adc_bits must be in 0..32 (0 = no quantization), got {}", adc_bits));
  if (transport_delay_samples < 0 || transport_delay_samples > 1000)
    return fail(fmt::format("sensors.transport_delay_samples must be in 0..1000, got {}",
                            transport_delay_samples));
  return true;
}

double Iso6358MassFlow(double C, double b, double p_up, double p_down, double T_up,
                       double laminar_ratio) {
  if (!(p_up > 0.0) || !(p_down < p_up)) return 0.0;
  const double base = C * kRho0 * p_up * std::sqrt(kT0 / T_up);
  const double r = std::max(p_down, 0.0) / p_up;
  if (r <= b) return base;  // choked (sonic) flow
  auto subsonic = [b](double ratio) {
    const double s = (ratio - b) / (1.0 - b);
    return std::sqrt(std::max(0.0, 1.0 - s * s));
  };
  if (r > laminar_ratio) return base * subsonic(laminar_ratio) * (1.0 - r) / (1.0 - laminar_ratio);
  return base * subsonic(r);
}

// ---------------------------------------------------------------------------

IpaSimulator::IpaSimulator(IpaParameters parameters, double Ts, std::uint64_t seed)
    : p_(std::move(parameters)), Ts_(Ts), seed_(seed) {
  std::string error;
  PNEUMID_CHECK(p_.IsValid(&error), "invalid IPA parameters: {}", error);
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  // Fixed storage for the sample loop (see EventQueue and readings_).
  inlet_ = std::make_unique<ipa_detail::Valve>();
  exhaust_ = std::make_unique<ipa_detail::Valve>();
  inlet_b_ = std::make_unique<ipa_detail::Valve>();
  exhaust_b_ = std::make_unique<ipa_detail::Valve>();
  for (ipa_detail::Valve* v : {inlet_.get(), exhaust_.get(), inlet_b_.get(), exhaust_b_.get()})
    v->pending.Reserve(EventCapacity());
  readings_.resize(static_cast<std::size_t>(p_.transport_delay_samples) + 1);
  Reset();
}

IpaSimulator::~IpaSimulator() = default;

std::size_t IpaSimulator::EventCapacity() const {
  // An event pending at time t was queued by a command issued after t - D,
  // D = the longest valve delay. Commands come at PWM period starts and falling
  // edges (each at most once per PWM period T, period starts at least T apart)
  // and at sample instants (manual valve commands, every Ts); two may coincide.
  // Doubled for margin, capped: beyond the cap the queue grows (allocates).
  const double D = std::max(p_.open_delay, p_.close_delay);
  const double T = 1.0 / p_.pwm_frequency;
  const double pwm_events = 2.0 * (std::ceil(D / T) + 1.0);
  const double sample_events = std::ceil(D / Ts_) + 1.0;
  const double bound = 2.0 * (pwm_events + sample_events) + 4.0;
  return static_cast<std::size_t>(std::min(bound, 65536.0));
}

void IpaSimulator::Reset() {
  rng_.seed(seed_);
  normal_.reset();
  double pa0 = p_.atmospheric_pressure;
  double pb0 = p_.supply_pressure + p_.atmospheric_pressure;
  if (p_.mode == IpaMode::kPosition) {
    // At rest in balance: chamber B at half the supply gauge pressure, chamber
    // A at the pressure whose force balances it.
    pb0 = p_.atmospheric_pressure + 0.5 * p_.supply_pressure;
    pa0 = p_.atmospheric_pressure + p_.AreaB() / p_.AreaA() * 0.5 * p_.supply_pressure;
  }
  x_ = {pa0 / kBar, pb0 / kBar, p_.piston_position / kMm, 0.0, 0.0, 0.0, pa0 / kBar,
        pa0 / kBar, 0.0};
  t_ = 0.0;
  dt_ = 1e-4;
  steps_ = 0;
  sample_ = 0;
  for (ipa_detail::Valve* v : {inlet_.get(), exhaust_.get(), inlet_b_.get(), exhaust_b_.get()}) {
    v->open = false;
    v->command = false;
    v->pending.clear();  // keeps its storage
  }
  duty_ = 0.0;
  period_start_ = 0.0;
  falling_edge_ = -1.0;
  exhaust_pulse_ = false;
  load_disturbance_ = 0.0;
  for (double& r : readings_) r = SenseOutput();
  reading_head_ = 0;
}

void IpaSimulator::SetState(double p_a, double p_b, double x) {
  PNEUMID_CHECK(std::isfinite(p_a) && p_a > 0.0 && std::isfinite(p_b) && p_b > 0.0,
                "IPA state: chamber pressures must be positive (absolute), got p_a = {} Pa, "
                "p_b = {} Pa",
                p_a, p_b);
  PNEUMID_CHECK(std::isfinite(x) && x >= 0.0 && x <= p_.stroke,
                "IPA state: piston position {} m is outside the stroke 0..{} m", x, p_.stroke);
  x_[0] = p_a / kBar;
  x_[1] = p_b / kBar;
  if (p_.mode == IpaMode::kPosition) x_[2] = x / kMm;
  x_[3] = 0.0;
  x_[6] = x_[0];
  x_[7] = x_[0];
  x_[8] = 0.0;
  for (double& r : readings_) r = SenseOutput();
  reading_head_ = 0;
}

double IpaSimulator::Measure() { return readings_[reading_head_]; }

double IpaSimulator::pressure_a() const { return x_[0] * kBar; }
double IpaSimulator::pressure_b() const { return x_[1] * kBar; }
double IpaSimulator::pressure_manifold() const {
  return (p_.tube_conductance > 0.0 ? x_[7] : x_[0]) * kBar;
}
double IpaSimulator::position() const { return x_[2] * kMm; }
double IpaSimulator::velocity() const { return x_[3]; }
double IpaSimulator::bristle_deflection() const { return x_[8] * kMicron; }
double IpaSimulator::force() const {
  return p_.AreaA() * (pressure_a() - p_.atmospheric_pressure) + p_.force_offset;
}
double IpaSimulator::rod_force() const {
  return p_.AreaA() * (pressure_a() - p_.atmospheric_pressure) -
         p_.AreaB() * (pressure_b() - p_.atmospheric_pressure);
}
double IpaSimulator::chamber_mass_a() const {
  const double V = p_.dead_volume_a + p_.AreaA() * position();
  return pressure_a() * V / (p_.gas_constant * p_.temperature);
}
double IpaSimulator::mass_in_a() const { return x_[4] * kGram; }
double IpaSimulator::mass_out_a() const { return x_[5] * kGram; }

std::map<std::string, double> IpaSimulator::Extras() const {
  std::map<std::string, double> e{{"p_a [Pa]", pressure_a()}, {"p_b [Pa]", pressure_b()}};
  if (p_.mode == IpaMode::kPosition) {
    e["x [m]"] = position();
    e["v [m/s]"] = velocity();
  }
  return e;
}

std::string IpaSimulator::Describe() const {
  return fmt::format("ipa ({} mode, {} PWM {:g} Hz, bore {:g} mm)", ToString(p_.mode),
                     ToString(p_.pwm_mode), p_.pwm_frequency, p_.bore * 1e3);
}

double IpaSimulator::Quantize(double volts) const {
  if (p_.adc_bits == 0) return volts;
  const double codes = std::ldexp(1.0, p_.adc_bits);
  const double lsb = 2.0 * p_.adc_range / codes;
  const double code = std::clamp(std::round(volts / lsb), -codes / 2.0, codes / 2.0 - 1.0);
  return code * lsb;
}

double IpaSimulator::SenseOutput() {
  const double n = normal_(rng_);
  if (p_.mode == IpaMode::kForce) {
    const double sensed = p_.pressure_filter_time_constant > 0.0 ? x_[6] * kBar : pressure_a();
    const double gauge = sensed + p_.pressure_noise * n - p_.atmospheric_pressure;
    const double volts = Quantize(gauge / p_.pressure_full_scale * p_.adc_range);
    return p_.AreaA() * volts / p_.adc_range * p_.pressure_full_scale + p_.force_offset +
           load_disturbance_;
  }
  double pos = position() + p_.position_noise * n;
  if (p_.position_resolution > 0.0)
    pos = std::round(pos / p_.position_resolution) * p_.position_resolution;
  const double volts = Quantize(pos / p_.stroke * p_.adc_range);
  return volts / p_.adc_range * p_.stroke + load_disturbance_;
}

void IpaSimulator::Rhs(const State& x, State& dxdt, const Openings& open) const {
  const double pa = x[0] * kBar;
  const double pb = x[1] * kBar;
  const bool moving = p_.mode == IpaMode::kPosition;
  const double pos = moving ? x[2] * kMm : p_.piston_position;
  const double v = moving ? x[3] : 0.0;
  const double ps = p_.supply_pressure + p_.atmospheric_pressure;
  const double patm = p_.atmospheric_pressure;
  const double T = p_.temperature;
  const double rl = p_.laminar_ratio;
  const double Aa = p_.AreaA();
  const double Ab = p_.AreaB();
  const double Va = std::max(p_.dead_volume_a + Aa * pos, 0.1 * p_.dead_volume_a);
  const double Vb = std::max(p_.dead_volume_b + Ab * (p_.stroke - pos), 0.1 * p_.dead_volume_b);

  // Valves: inlet (supply <-> valve side) and exhaust (valve side <->
  // atmosphere). The valve side is chamber A itself or, with a tube, the valve
  // manifold, which the tube connects to chamber A.
  const bool tube = p_.tube_conductance > 0.0;
  const double pv = tube ? x[7] * kBar : pa;
  // Mass flows (kg/s) into and out of a volume at pressure pv through an inlet
  // valve open for the fraction `in` and an exhaust valve open for `out`.
  auto valve_flows = [&](double pv, double in, double out, double& m_in, double& m_out) {
    m_in = m_out = 0.0;
    if (in > 0.0) {
      const double C = p_.inlet_conductance, b = p_.inlet_critical_ratio;
      m_in += in * Iso6358MassFlow(C, b, ps, pv, T, rl);
      m_out += in * Iso6358MassFlow(C, b, pv, ps, T, rl);
    }
    if (out > 0.0) {
      const double C = p_.exhaust_conductance, b = p_.exhaust_critical_ratio;
      m_out += out * Iso6358MassFlow(C, b, pv, patm, T, rl);
      m_in += out * Iso6358MassFlow(C, b, patm, pv, T, rl);
    }
  };
  double in_v = 0.0, out_v = 0.0;  // mass flows entering / leaving the valve side, kg/s
  valve_flows(pv, open.in_a, open.out_a, in_v, out_v);
  double in_a = in_v, out_a = out_v;  // mass flows entering / leaving chamber A, kg/s
  if (tube) {
    const double C = p_.tube_conductance, b = p_.tube_critical_ratio;
    in_a = Iso6358MassFlow(C, b, pv, pa, T, rl);
    out_a = Iso6358MassFlow(C, b, pa, pv, T, rl);
  }
  // Chamber B: its own valves (position mode, the same valve type as A's) or
  // the supply line through the (relieving) regulator (force mode).
  double in_b = 0.0, out_b = 0.0;
  if (moving) {
    valve_flows(pb, open.in_b, open.out_b, in_b, out_b);
  } else {
    const double C = p_.supply_line_conductance, b = p_.supply_line_critical_ratio;
    in_b = Iso6358MassFlow(C, b, ps, pb, T, rl);
    out_b = Iso6358MassFlow(C, b, pb, ps, T, rl);
  }

  const double RT = p_.gas_constant * T;
  const double dVa = Aa * v;
  const double dVb = -Ab * v;
  // The valves' flows carry the charging and discharging coefficients. The
  // tube's flow joins two volumes of gas at the same temperature: it enters
  // both with coefficient 1, so it moves p V from one to the other without
  // creating any (different coefficients on its two ends would pump pressure
  // up as the gas swings back and forth), and a wide tube gives the response
  // of the valves on the chamber.
  const double ka_in = tube ? 1.0 : p_.alpha_in, ka_out = tube ? 1.0 : p_.alpha_out;
  const double dpa = RT / Va * (ka_in * in_a - ka_out * out_a) - p_.alpha * pa * dVa / Va;
  const double dpb =
      RT / Vb * (p_.alpha_in * in_b - p_.alpha_out * out_b) - p_.alpha * pb * dVb / Vb;
  dxdt[0] = dpa / kBar;
  dxdt[1] = dpb / kBar;
  dxdt[4] = in_a / kGram;
  dxdt[5] = out_a / kGram;
  const double tf = p_.pressure_filter_time_constant;
  dxdt[6] = tf > 0.0 ? (x[0] - x[6]) / tf : 0.0;
  dxdt[7] = tube ? RT / p_.manifold_volume *
                       (p_.alpha_in * in_v - p_.alpha_out * out_v + out_a - in_a) / kBar
                 : 0.0;
  dxdt[8] = 0.0;
  if (!moving) {
    dxdt[2] = 0.0;
    dxdt[3] = 0.0;
    return;
  }
  // Piston and load: pressure force, friction [4], end stops (penalty).
  const double Fp = Aa * (pa - patm) - Ab * (pb - patm);
  const double vs = p_.stribeck_velocity;
  const double g = p_.coulomb_friction +
                   (p_.static_friction - p_.coulomb_friction) * std::exp(-(v / vs) * (v / vs));
  double Ff = p_.viscous_friction * v;
  if (p_.lugre_stiffness > 0.0) {
    const double z = x[8] * kMicron;
    const double dz = g > 0.0 ? v - p_.lugre_stiffness * std::abs(v) * z / g : 0.0;
    Ff += p_.lugre_stiffness * z + p_.lugre_damping * dz;
    dxdt[8] = dz / kMicron;
  } else {
    Ff += g * std::tanh(v / p_.friction_smoothing_velocity);
  }
  double Fstop = 0.0;
  if (pos < 0.0) Fstop = -p_.end_stop_stiffness * pos - p_.end_stop_damping * std::min(v, 0.0);
  if (pos > p_.stroke)
    Fstop = -p_.end_stop_stiffness * (pos - p_.stroke) - p_.end_stop_damping * std::max(v, 0.0);
  dxdt[2] = v / kMm;
  dxdt[3] = (Fp - Ff + Fstop) / p_.mass;
}

void IpaSimulator::Integrate(double t0, double t1, const Openings& open) {
  if (!(t1 > t0)) return;
  namespace odeint = boost::numeric::odeint;
  using Stepper = odeint::runge_kutta_dopri5<State>;
  auto stepper = odeint::make_controlled<Stepper>(p_.absolute_tolerance, p_.relative_tolerance);
  auto system = [this, &open](const State& x, State& dxdt, double /*t*/) { Rhs(x, dxdt, open); };
  State dxdt;
  system(x_, dxdt, t0);
  double t = t0;
  double dt = dt_;
  int failures = 0;
  while (t1 - t > 1e-15 * std::max(1.0, t1)) {
    double step = std::min(dt, t1 - t);
    const bool clipped = step < dt;
    if (stepper.try_step(system, x_, dxdt, t, step) == odeint::success) {
      ++steps_;
      failures = 0;
      dt = clipped ? std::max(dt, step) : step;
    } else {
      dt = step;
      if (++failures > 200 || dt < 1e-14)
        throw std::runtime_error(fmt::format(
            "IPA simulation: step size underflow at t = {} s (p_a = {} Pa)", t, pressure_a()));
    }
  }
  dt_ = std::min(dt, 1e-3);
  for (double v : x_)
    if (!std::isfinite(v))
      throw std::runtime_error(fmt::format("IPA simulation: non-finite state at t = {} s", t1));
}

void IpaSimulator::Command(ipa_detail::Valve& valve, bool on, double t) {
  if (valve.command == on) return;
  valve.command = on;
  const double t_phys = t + (on ? p_.open_delay : p_.close_delay);
  while (!valve.pending.empty() && valve.pending.back().time >= t_phys) valve.pending.pop_back();
  valve.pending.push_back(ipa_detail::ValveEvent{t_phys, on});
}

void IpaSimulator::StartPositionPeriod(double T) {
  // Signed duty: u > 0 fills A and vents B, u < 0 the reverse, for |u| T; all
  // valves closed for the rest of the period. Pulses shorter than the minimum
  // width do not open the valves; off times shorter than it do not close them.
  const double a = std::min(std::abs(duty_), 1.0);
  const bool full = HeldOpen(a, T, p_.min_pulse_width);
  const bool pulse = full || (a > 0.0 && a * T >= p_.min_pulse_width);
  const bool out = duty_ > 0.0;
  Command(out ? *inlet_ : *inlet_b_, pulse, t_);
  Command(out ? *exhaust_b_ : *exhaust_, pulse, t_);
  Command(out ? *inlet_b_ : *inlet_, false, t_);
  Command(out ? *exhaust_ : *exhaust_b_, false, t_);
  falling_edge_ = (pulse && !full) ? t_ + a * T : -1.0;
  exhaust_pulse_ = false;
}

void IpaSimulator::AdvanceTo(double t_end, bool pwm, bool inlet_cmd, bool exhaust_cmd) {
  const double T = 1.0 / p_.pwm_frequency;
  const bool position = p_.mode == IpaMode::kPosition;
  if (!pwm) {
    Command(*inlet_, inlet_cmd, t_);
    Command(*exhaust_, exhaust_cmd, t_);
    if (position) {
      Command(*inlet_b_, inlet_cmd, t_);
      Command(*exhaust_b_, exhaust_cmd, t_);
    }
    falling_edge_ = -1.0;
  } else if (period_start_ < t_ - kEventTol) {
    period_start_ = t_;  // restart the PWM generator after manual valve commands
  }
  while (true) {
    // Events due now.
    if (pwm && std::abs(t_ - period_start_) <= kEventTol) {
      // A new PWM period latches the duty held now.
      if (position) {
        StartPositionPeriod(T);
      } else {
        const double d = duty_;
        const double w_in = d * T, w_out = (1.0 - d) * T;
        const bool in_pulse = d >= 1.0 || (d > 0.0 && w_in >= p_.min_pulse_width);
        exhaust_pulse_ = d <= 0.0 || (d < 1.0 && w_out >= p_.min_pulse_width);
        Command(*inlet_, in_pulse, t_);
        Command(*exhaust_, d <= 0.0 && exhaust_pulse_, t_);
        falling_edge_ = (d > 0.0 && d < 1.0) ? t_ + w_in : -1.0;
      }
      period_start_ += T;
    }
    if (pwm && falling_edge_ >= 0.0 && std::abs(t_ - falling_edge_) <= kEventTol) {
      Command(*inlet_, false, t_);
      Command(*exhaust_, exhaust_pulse_, t_);
      if (position) {
        Command(*inlet_b_, false, t_);
        Command(*exhaust_b_, false, t_);
      }
      falling_edge_ = -1.0;
    }
    for (ipa_detail::Valve* v : {inlet_.get(), exhaust_.get(), inlet_b_.get(), exhaust_b_.get()}) {
      while (!v->pending.empty() && v->pending.front().time <= t_ + kEventTol) {
        v->open = v->pending.front().open;
        v->pending.pop_front();
      }
    }
    if (t_ >= t_end - kEventTol) break;
    double t_next = t_end;
    if (pwm) {
      t_next = std::min(t_next, period_start_);
      if (falling_edge_ > t_) t_next = std::min(t_next, falling_edge_);
    }
    for (const ipa_detail::Valve* v :
         {inlet_.get(), exhaust_.get(), inlet_b_.get(), exhaust_b_.get()})
      if (!v->pending.empty()) t_next = std::min(t_next, v->pending.front().time);
    Integrate(t_, t_next,
              Openings{inlet_->open ? 1.0 : 0.0, exhaust_->open ? 1.0 : 0.0,
                       inlet_b_->open ? 1.0 : 0.0, exhaust_b_->open ? 1.0 : 0.0});
    t_ = t_next;
  }
  t_ = t_end;
}

void IpaSimulator::Advance(double u) {
  const bool position = p_.mode == IpaMode::kPosition;
  PNEUMID_CHECK(std::isfinite(u), "IPA input ({}, %) must be finite, got {}",
                position ? "signed valve command" : "PWM duty", u);
  duty_ = std::clamp(u, position ? -100.0 : 0.0, 100.0) / 100.0;
  ++sample_;
  const double t_end = static_cast<double>(sample_) * Ts_;
  if (p_.pwm_mode == PwmMode::kSwitching) {
    AdvanceTo(t_end, true, false, false);
  } else {
    // Effective open fraction of each valve over a PWM period.
    const double T = 1.0 / p_.pwm_frequency;
    auto fraction = [&](double w) {
      if (w >= T) return 1.0;
      if (w <= 0.0 || w < p_.min_pulse_width) return 0.0;
      return std::clamp((w - p_.open_delay + p_.close_delay) / T, 0.0, 1.0);
    };
    if (position) {
      // An off time shorter than the minimum pulse does not close the valves.
      const double a = std::min(std::abs(duty_), 1.0);
      const double f = HeldOpen(a, T, p_.min_pulse_width) ? 1.0 : fraction(a * T);
      Integrate(t_, t_end, duty_ > 0.0 ? Openings{f, 0.0, 0.0, f} : Openings{0.0, f, f, 0.0});
    } else {
      Integrate(t_, t_end, Openings{fraction(duty_ * T), fraction((1.0 - duty_) * T), 0.0, 0.0});
    }
    t_ = t_end;
  }
  PushReading();
}

void IpaSimulator::PushReading() {
  // Delay line: the oldest reading (just returned by Measure) is replaced by the
  // newest, and the next oldest becomes the head.
  readings_[reading_head_] = SenseOutput();
  reading_head_ = (reading_head_ + 1) % readings_.size();
}

void IpaSimulator::AdvanceValves(bool inlet_open, bool exhaust_open) {
  ++sample_;
  AdvanceTo(static_cast<double>(sample_) * Ts_, false, inlet_open, exhaust_open);
  PushReading();
}

Actuator IpaSimulator::actuator() const {
  Actuator a = IpaActuator(p_.mode);
  const double w = 100.0 * p_.min_pulse_width * p_.pwm_frequency;
  const bool position = p_.mode == IpaMode::kPosition;
  if (position) {
    a.y_min = 0.0;
    a.y_max = p_.stroke;
  }
  if (w > 0.0 && w < 50.0) {
    a.input_gaps =
        position
            ? std::vector<InputGap>{{-100.0, -100.0 + w}, {-w, 0.0}, {0.0, w}, {100.0 - w, 100.0}}
            : std::vector<InputGap>{{0.0, w}, {100.0 - w, 100.0}};
  }
  return a;
}

}  // namespace pneumid
