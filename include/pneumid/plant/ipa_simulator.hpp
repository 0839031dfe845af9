// Physics simulator of the Intelligent Pneumatic Actuator (IPA): a
// double-acting cylinder driven by 2/2 on/off solenoid valves under PWM.
//   force mode     the rod is held; chamber A is filled and vented by an inlet
//                  and an exhaust valve driven by one PWM signal, chamber B is
//                  held at the regulated supply pressure (the paper's setup)
//   position mode  the piston moves; each chamber has its own inlet and
//                  exhaust valve, driven by one signed command (below)
//
// Convention (used everywhere in pneumid; the paper's text and its Eq. 1 swap
// the indices):
//   chamber A  the regulated chamber on the full-bore (cap) side, area A_a = pi/4 bore^2,
//              volume V_a = V_a0 + A_a x; filled by the inlet valve from the
//              supply and vented by the exhaust valve to atmosphere ("chamber 1",
//              pressure "P_2" in the paper's text)
//   chamber B  the supply chamber on the rod side, area A_b = A_a - pi/4 rod^2,
//              volume V_b = V_b0 + A_b (stroke - x); connected to the pressure
//              regulator through a supply line
//   x          piston position from the chamber-A end (m); positive force pushes
//              the rod out (x increasing)
//   F_rod      = A_a (p_a - p_atm) - A_b (p_b - p_atm), the force on the rod
//   F          (force-mode output) = A_a (p_a,meas - p_atm) + force_offset: the
//              rod force with the constant supply-chamber term A_b (p_s - p_atm)
//              tared out, as the paper computes its force from the chamber-A
//              pressure with the supply pressure taken as constant. F = 0 with
//              chamber A vented (duty in the dead band, e.g. 0.61 %), F ~ 129 N
//              at 82 % duty with the default parameters.
//   u          force mode: PWM duty cycle in percent (0..100): in each PWM
//              period of length T_pwm the inlet valve is commanded open for
//              u/100 T_pwm and the exhaust valve for the rest of the period
//              (complementary drive).
//              position mode: signed command in percent (-100..100): for u > 0
//              chamber A's inlet and chamber B's exhaust are open for u/100 T_pwm
//              of each period (A fills, B vents, the piston moves out), for
//              u < 0 chamber B's inlet and chamber A's exhaust for |u|/100
//              T_pwm; all four valves are closed for the rest of the period
//              (the chambers hold their gas). The same pulse width limit makes
//              the dead band around 0, and an off time shorter than it does
//              not close the valves (|u| near 100 acts as 100).
//              Position-mode state at rest (Reset): chamber B at half the
//              supply gauge pressure, chamber A at the pressure that balances
//              the piston, A_a (p_a - p_atm) = A_b (p_b - p_atm).
//
// Physics:
// [1] E. Richer, Y. Hurmuzlu, A high performance pneumatic force actuator
//     system: Part I - nonlinear mathematical model, ASME J. Dyn. Sys. Meas.
//     Control 122(3), 2000, eq. 8 (chamber energy equation):
//       dp/dt = (R T_s / V) (alpha_in m_in - alpha_out m_out) - alpha p (dV/dt) / V
//     with alpha_in = gamma (adiabatic charging), alpha_out ~ 1, alpha ~ 1.2.
// [2] ISO 6358-1:2013, Pneumatic fluid power - Determination of flow-rate
//     characteristics of components using compressible fluids, eq. 1-2:
//       r = p_down / p_up
//       m = C rho_0 p_up sqrt(T_0 / T_up)                         r <= b (choked)
//       m = C rho_0 p_up sqrt(T_0 / T_up) sqrt(1 - ((r - b)/(1 - b))^2)   b < r < 1
//     rho_0 = 1.185 kg/m^3, T_0 = 293.15 K (ISO 8778 reference atmosphere).
//     Above r = laminar_ratio the flow is continued linearly to zero at r = 1
//     (laminar region), so that dm/dp stays finite and the ODE well behaved.
// [3] Valve dynamics: the valve opens open_delay after the command edge and
//     closes close_delay after the falling edge; command pulses shorter than
//     min_pulse_width do not open the valve (dead band at small and large duty).
// [4] Friction: Stribeck curve with a smoothed sign, B. Armstrong-Helouvry,
//     Control of Machines with Friction, 1991:
//       g(v) = F_c + (F_s - F_c) exp(-(v/v_s)^2)
//       F_f  = g(v) tanh(v/v_eps) + b v
//     or (lugre_stiffness sigma0 > 0) the LuGre model, C. Canudas de Wit,
//     H. Olsson, K. J. Astrom, P. Lischinsky, A new model for control of
//     systems with friction, IEEE TAC 40(3), 1995, eq. 2-5:
//       dz/dt = v - sigma0 |v| z / g(v)
//       F_f   = sigma0 z + sigma1 dz/dt + b v
//     which sticks (pre-sliding deflection z <= F_s / sigma0) until the net
//     force exceeds F_s, where the smoothed sign creeps at v ~ v_eps F / F_s.
//     Piston: m dv/dt = A_a (p_a - p_atm) - A_b (p_b - p_atm) - F_f + F_stop,
//     F_stop a stiff spring-damper at each end of the stroke.
// Sensors: position (position mode): potentiometer or encoder reading plus
// Gaussian noise, rounded to position_resolution (an encoder's count; 0: none),
// 0..stroke -> 0..10 V through the same ADC. Force mode: pressure transducer with an optional
// first-order low-pass (time constant pressure_filter_time_constant: transducer bandwidth, the RC
// anti-aliasing filter before the ADC, digital smoothing of the PWM ripple), Gaussian noise,
// 0..full scale -> 0..10 V, read by a bipolar 16-bit ADC over +-10 V (NI PCI-6221: 20 V / 2^16 =
// 0.305 mV per code), output delayed by transport_delay_samples sample periods. Integration:
// Boost.Odeint runge_kutta_dopri5 with error control, restarted at every valve switching instant
// (switching mode) or sample (averaged mode).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "pneumid/plant/plant.hpp"

namespace pneumid {

namespace ipa_detail {
struct Valve;  // src/plant/ipa_valve.hpp
}  // namespace ipa_detail

/// Force mode: rod fixed, output force in N (the paper's identification setup).
/// Position mode: piston and load move, output position in m.
enum class IpaMode { kForce, kPosition };
/// "force", "position".
std::string ToString(IpaMode mode);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
IpaMode IpaModeFromString(const std::string& name);

/// Switching: every valve switching event of the PWM signal is simulated
/// (pressure ripple, PWM latch, exact dead band); the default, because it is
/// what the real valves do and it still runs thousands of times faster than
/// real time. Averaged: valve flows multiplied by the effective open fraction
/// of the period (no ripple, duty applied at once), faster.
enum class PwmMode { kSwitching, kAveraged };
/// "switching" (also accepted: "pwm"), "averaged".
std::string ToString(PwmMode mode);
/// Inverse of ToString (accepts "pwm" for switching); throws InvalidArgument listing
/// the valid names.
PwmMode PwmModeFromString(const std::string& name);

/// All physical parameters of the IPA. Defaults: the calibrated actuator of
/// docs/simulator.md (config/ipa_default.toml lists the same values).
/// Pressures are absolute unless named gauge.
struct IpaParameters {
  IpaMode mode = IpaMode::kForce;          ///< output force in N, or position in m
  PwmMode pwm_mode = PwmMode::kSwitching;  ///< valve switching simulated, or averaged flows

  // [cylinder]
  double bore = 0.020266;  ///< m, piston diameter (effective; calibrated)
  double rod = 0.006;      ///< m, rod diameter (chamber B side)
  double stroke = 0.10;    ///< m
  double piston_position =
      0.05;  ///< m from the chamber-A end (fixed in force mode, initial otherwise)
  double dead_volume_a = 10.0e-6;  ///< m^3, chamber A ports, valve manifold and a short tube
  double dead_volume_b = 10.0e-6;  ///< m^3, chamber B ports and tubing

  // [supply]
  double supply_pressure = 0.6e6;           ///< Pa gauge, regulated supply
  double atmospheric_pressure = 101325.0;   ///< Pa
  double temperature = 293.15;              ///< K, supply (and chamber) gas temperature
  double supply_line_conductance = 1.0e-8;  ///< m^3/(s Pa), regulator + line to chamber B
  double supply_line_critical_ratio = 0.3;  ///< -, ISO 6358 b of that supply line

  // [gas]
  double gas_constant = 287.0;  ///< J/(kg K), air
  double alpha_in = 1.4;        ///< charging coefficient [1] (gamma: adiabatic)
  double alpha_out = 1.0;       ///< discharging coefficient [1] (1: isothermal)
  double alpha = 1.2;           ///< coefficient of the volume-change term [1]

  // [valves]  sonic conductance in m^3/(s Pa): 1 dm^3/(s bar) = 1e-8 m^3/(s Pa)
  double inlet_conductance = 1.05e-8;     ///< m^3/(s Pa), C of the inlet valve
  double inlet_critical_ratio = 0.473;    ///< -, b of the inlet valve
  double exhaust_conductance = 3.9e-8;    ///< m^3/(s Pa), C of the exhaust valve
  double exhaust_critical_ratio = 0.106;  ///< -, b of the exhaust valve
  double laminar_ratio = 0.999;           ///< -, pressure ratio above which flow is linear in dp
  double open_delay = 0.0005;             ///< s, command rising edge -> valve open
  double close_delay = 0.001457;          ///< s, command falling edge -> valve closed
  double min_pulse_width = 0.0005;        ///< s, shorter command pulses do not open the valve
  /// m^3/(s Pa), ISO 6358 C of the tube (and ports) between the valve manifold
  /// and chamber A; 0: the valves sit on the chamber (no tube, no manifold).
  double tube_conductance = 0.0;
  double tube_critical_ratio = 0.3;  ///< -, ISO 6358 b of that tube
  /// m^3, volume of the valve manifold on the valves' side of the tube (used
  /// only with a tube; chamber A's own volume is dead_volume_a + A_a x).
  double manifold_volume = 2.0e-6;

  // [pwm]
  double pwm_frequency = 300.0;  ///< Hz (3 periods per 0.01 s sample: no aliased ripple)

  // [mechanics] (position mode)
  double mass = 1.0;                            ///< kg, piston + rod + load
  double viscous_friction = 40.0;               ///< N s/m
  double coulomb_friction = 6.0;                ///< N
  double static_friction = 9.0;                 ///< N (Stribeck peak)
  double stribeck_velocity = 0.01;              ///< m/s
  double friction_smoothing_velocity = 1.0e-3;  ///< m/s, width of the smoothed sign
  double end_stop_stiffness = 1.0e6;            ///< N/m
  double end_stop_damping = 1000.0;             ///< N s/m
  /// N/m, LuGre bristle stiffness sigma0 [4]; 0: the static Stribeck map with
  /// a smoothed sign (the piston creeps under forces below breakaway).
  double lugre_stiffness = 0.0;
  double lugre_damping = 0.0;  ///< N s/m, LuGre micro-damping sigma1 [4]

  // [sensors]
  double pressure_noise = 150.0;       ///< Pa, standard deviation of the transducer noise
  double pressure_full_scale = 1.0e6;  ///< Pa gauge at 10 V transducer output
  /// s, time constant of the first-order low-pass between the chamber-A
  /// pressure and the ADC (transducer bandwidth, RC anti-aliasing filter,
  /// digital smoothing of the PWM ripple); 0: none. The default is calibrated
  /// to the paper's rig (docs/simulator.md, "The default twin").
  double pressure_filter_time_constant = 0.21564;
  double position_noise = 1.0e-5;  ///< m, standard deviation (position mode)
  /// m, position sensor resolution (an encoder's count); 0: continuous (a
  /// potentiometer, then only the ADC quantizes).
  double position_resolution = 0.0;
  int adc_bits = 16;                ///< ADC resolution; 0 disables quantization
  double adc_range = 10.0;          ///< V, bipolar input range +-adc_range
  int transport_delay_samples = 0;  ///< sample periods between reading and output
  double force_offset = 0.0;        ///< N added to the force output

  // [simulation]
  double relative_tolerance = 1e-6;  ///< odeint error control (states scaled to bar, mm, g)
  double absolute_tolerance = 1e-6;  ///< odeint absolute error bound (same scaled states)

  /// Derived areas (m^2).
  double AreaA() const;
  double AreaB() const;  ///< chamber B annulus: pi/4 (bore^2 - rod^2), m^2

  /// False (with a message naming the parameter and its value) when a value is
  /// out of its physical range.
  bool IsValid(std::string* error) const;
};

/// The defaults of a mode: IpaParameters{} for force mode; for position mode
/// the position rig (docs/position.md): the same cylinder with four small fast
/// valves, inlet C = 0.1 dm^3/(s bar), exhaust 0.12 dm^3/(s bar), opening
/// 0.3 ms, closing 0.5 ms, minimum pulse 0.3 ms. The force twin's valves are
/// sized for the force loop: one minimum pulse of theirs moves the free piston
/// by about 14 mm (its air springs, p A^2 / V ~ 3 kN/m, take up the pulse's
/// 40 N), which no position loop can use.
IpaParameters DefaultIpaParameters(IpaMode mode);

/// Reads parameters from a TOML file (keys as in config/ipa_default.toml, every
/// key optional). Keys not in the file take DefaultIpaParameters of the file's
/// [simulation] mode or, when the file names none, of `mode`. Throws DataError
/// naming the file, the key and (for syntax errors) line and column, for
/// unknown keys, wrong types and values that fail IsValid().
IpaParameters LoadIpaParameters(const std::string& path, IpaMode mode = IpaMode::kForce);

/// One numeric parameter of IpaParameters, named by its TOML key
/// ("valves.inlet_conductance"), with its unit and the range physics allows
/// (docs/simulator.md, "Parameter ranges", gives the source of each range).
/// The range bounds the calibration (identify/ipa_calibration.hpp); values
/// outside it are not rejected by IsValid, which checks only what the
/// equations need.
struct IpaParameterInfo {
  std::string key;     ///< "section.name" as in config/ipa_default.toml
  std::string unit;    ///< SI unit, "" for ratios
  double lower = 0.0;  ///< lower end of the physical range, in `unit`
  double upper = 0.0;  ///< upper end of the physical range, in `unit`
  /// False for numerical settings and sensor scaling (tolerances, ADC range,
  /// noise) that a calibration does not estimate.
  bool calibratable = true;
};

/// Every floating-point parameter, in the order of config/ipa_default.toml.
const std::vector<IpaParameterInfo>& IpaParameterTable();
/// The table entry of a parameter named by its key or, when unique, by the
/// key's last part ("bore" -> "cylinder.bore").
/// @throws InvalidArgument naming the unknown or ambiguous name and listing the valid keys.
const IpaParameterInfo& FindIpaParameter(const std::string& name);
/// Value of a parameter named as FindIpaParameter accepts.
double GetIpaParameter(const IpaParameters& p, const std::string& name);
/// Sets a parameter named as FindIpaParameter accepts (no range check: call IsValid).
void SetIpaParameter(IpaParameters& p, const std::string& name, double value);
/// The parameters as TOML that LoadIpaParameters reads back to the same
/// values (every key, shortest round-trip decimals). `comment` lines, if any,
/// are written first as '#' comments.
std::string IpaParametersToToml(const IpaParameters& p, const std::string& comment = {});

/// ISO 6358 mass flow (kg/s) through a restriction of sonic conductance C
/// (m^3/(s Pa)) and critical ratio b from p_up to p_down (Pa, absolute), with
/// upstream temperature T_up (K) and the laminar continuation above
/// laminar_ratio (see [2]). Zero when p_down >= p_up.
double Iso6358MassFlow(double C, double b, double p_up, double p_down, double T_up,
                       double laminar_ratio = 0.999);

/// The IPA as a Plant. Input: PWM duty in percent (clamped to 0..100) in force
/// mode, signed command in percent (clamped to -100..100) in position mode.
/// Output: force in N (force mode) or position in m (position mode), through
/// the sensor model. Measure, Advance and AdvanceValves do not allocate
/// (storage is sized at construction), so the simulator can run on the
/// real-time loop thread.
class IpaSimulator final : public Plant {
 public:
  /// Throws InvalidArgument when the parameters are not valid or Ts <= 0.
  IpaSimulator(IpaParameters parameters, double Ts, std::uint64_t seed = 1);
  ~IpaSimulator() override;

  void Reset() override;
  double Measure() override;
  void Advance(double u) override;
  double Ts() const override { return Ts_; }
  double time() const override { return t_; }
  /// "p_a [Pa]", "p_b [Pa]" (absolute, true values now); in position mode also
  /// "x [m]" and "v [m/s]".
  std::map<std::string, double> Extras() const override;
  std::string Describe() const override;
  /// IpaActuator(mode) with the valves' input gaps (and, in position mode,
  /// the output range 0..stroke); plant/actuator.hpp.
  Actuator actuator() const override;

  /// Sets the true state now: chamber pressures p_a, p_b (Pa absolute) and,
  /// in position mode, piston position x (m, within the stroke) at rest. The
  /// sensor delay line is refilled with readings of this state, so Measure()
  /// returns it at once: the initial state of a measured experiment.
  /// @throws InvalidArgument for non-positive pressures or x outside the stroke.
  void SetState(double p_a, double p_b, double x);

  /// Holds the valve commands (true = energized/open) for one sample period,
  /// bypassing the PWM generator; valve delays still apply. In position mode
  /// both chambers' inlets get inlet_open and both exhausts exhaust_open
  /// (false, false holds both chambers; false, true vents both).
  void AdvanceValves(bool inlet_open, bool exhaust_open);

  const IpaParameters& parameters() const { return p_; }  ///< as given at construction
  /// True (noise-free) state now.
  double pressure_a() const;  ///< Pa absolute
  double pressure_b() const;  ///< Pa absolute
  double position() const;    ///< m
  double velocity() const;    ///< m/s
  /// Force output without sensor effects: A_a (p_a - p_atm) + force_offset (N).
  double force() const;
  /// Rod force A_a (p_a - p_atm) - A_b (p_b - p_atm) (N).
  double rod_force() const;
  /// Gas mass in chamber A by the ideal gas law p V / (R T) (kg).
  double chamber_mass_a() const;
  /// Pressure in the valve manifold (Pa absolute; equals p_a without a tube).
  double pressure_manifold() const;
  /// Mass that has flowed into / out of chamber A since Reset (kg): through its
  /// valves, or through the tube when there is one.
  double mass_in_a() const;
  double mass_out_a() const;  ///< kg vented from chamber A since Reset (see mass_in_a)
  /// Number of odeint steps taken since Reset (for benchmarks).
  long long steps() const { return steps_; }

  /// LuGre bristle deflection z (m; 0 without LuGre).
  double bristle_deflection() const;

  /// Internal state, scaled for the error control: p_a, p_b [bar], x [mm],
  /// v [m/s], m_in_a, m_out_a [g], sensed p_a after the sensor filter [bar],
  /// valve manifold pressure [bar], LuGre bristle deflection z [um].
  using State = std::array<double, 9>;

 private:
  // Fraction of the interval each valve is open (averaged mode) or 0/1
  // (switching): chamber A's inlet and exhaust, chamber B's (position mode).
  struct Openings {
    double in_a = 0.0, out_a = 0.0, in_b = 0.0, out_b = 0.0;
  };

  // Advance, AdvanceValves and Measure do not allocate: the valve event queues
  // (src/plant/ipa_valve.hpp) and the sensor delay line are ring buffers sized
  // at construction.

  /// Upper bound on the events pending in one valve's queue: commands issued
  /// within the longest valve delay (PWM edges and sample instants).
  std::size_t EventCapacity() const;
  void Command(ipa_detail::Valve& valve, bool on, double t);
  void Integrate(double t0, double t1, const Openings& open);
  void Rhs(const State& x, State& dxdt, const Openings& open) const;
  /// Position mode: the PWM period starting now latches the signed duty.
  void StartPositionPeriod(double T);
  double SenseOutput();
  /// Appends SenseOutput() to the sensor delay line, dropping the oldest reading.
  void PushReading();
  double Quantize(double volts) const;
  void AdvanceTo(double t_end, bool pwm, bool inlet_cmd, bool exhaust_cmd);

  IpaParameters p_;
  double Ts_;
  std::uint64_t seed_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};

  State x_{};
  double t_ = 0.0;
  double dt_ = 1e-4;  // last accepted step size
  long long steps_ = 0;
  long long sample_ = 0;
  std::unique_ptr<ipa_detail::Valve> inlet_, exhaust_;      // chamber A's
  std::unique_ptr<ipa_detail::Valve> inlet_b_, exhaust_b_;  // chamber B's (position mode)
  double duty_ = 0.0;             // input held now (fraction 0..1; signed -1..1 in position mode)
  double period_start_ = 0.0;     // start of the next PWM period
  double falling_edge_ = -1.0;    // pending inlet->exhaust command switch in this period
  bool exhaust_pulse_ = false;    // the exhaust valve is pulsed in this period
  std::vector<double> readings_;  // sensor delay line (ring), transport_delay_samples + 1
  std::size_t reading_head_ = 0;  // index of the oldest reading (the one Measure returns)
};

}  // namespace pneumid
