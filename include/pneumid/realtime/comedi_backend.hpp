// Data-acquisition backend through libcomedi (NI PCI-6221 class cards).
//
// Signal chain (the paper's rig: one pressure transducer in, two valves out):
//   AI raw -> volts:  comedi_to_physical() with the card's software calibration
//                     polynomial when a calibration file exists (comedi_soft_calibrate),
//                     else the hardware-calibrated converter, else comedi_to_phys()
//                     with the nominal range;
//   volts -> pressure p = pressure_gain * V + pressure_offset        [Pa]
//   pressure -> force F = force_gain * p + force_offset               [N]
//     (e.g. F = p_s A_a - p A_b: force_gain = -A_b, force_offset = p_s A_a)
//   duty u (%) -> valve levels (AO volts, comedi_from_phys): the inlet valve driver
//     gets V_in = v_closed + u/100 (v_open - v_closed); the exhaust driver gets the
//     complementary level (100 - u) when exhaust = "complementary", or stays closed
//     when exhaust = "closed". The drivers generate the PWM (analog-level mode).
// Out-of-range readings: a raw value at either ADC rail (0 or maxdata), or a
// voltage outside [v_min, v_max] of the transducer, give IoStatus::kOutOfRange.
// Safe states: hold (valves-closed) writes v_closed to both outputs; release
// (exhaust-open) writes v_closed to the inlet and v_open to the exhaust.
//
// What is exercised without a card: the configuration, the conversion math
// (including comedi_to_phys/comedi_from_phys on the PCI-6221 ranges) and the
// error for a missing device. Reads and writes on a real card are not.
#pragma once

#include <cstdint>
#include <string>

#include "pneumid/realtime/io_backend.hpp"

namespace pneumid {

/// Analog reference of the input, as in comedi (AREF_GROUND, ...).
enum class AnalogReference { kGround = 0, kCommon = 1, kDiff = 2, kOther = 3 };
const char* ToString(AnalogReference a);  ///< "ground", "common", "diff", "other"
/// "ground", "common", "diff", "other". @throws InvalidArgument.
AnalogReference AnalogReferenceFromString(const std::string& s);

/// Device, channels and signal-chain constants of ComediBackend (chain above).
struct ComediConfig {
  std::string device = "/dev/comedi0";  ///< absolute path of the comedi device node
  // Analog input: pressure transducer.
  int ai_subdevice = 0;                              ///< M-series: subdevice 0 is AI
  int ai_channel = 0;                                ///< AI channel of the pressure transducer
  int ai_range = 0;                                  ///< range index (PCI-6221 AI range 0: +-10 V)
  AnalogReference ai_aref = AnalogReference::kDiff;  ///< AI reference (default differential)
  double v_min = 0.0;          ///< plausible transducer output window (V); outside -> out of range
  double v_max = 10.0;         ///< upper end of that window (V), > v_min
  double pressure_gain = 1e5;  ///< Pa per V (e.g. 0-10 V for 0-1 MPa)
  double pressure_offset = 0.0;  ///< Pa
  double force_gain = 1.0;       ///< N per Pa
  double force_offset = 0.0;     ///< N
  // Analog outputs: valve drivers.
  int ao_subdevice = 1;     ///< M-series: subdevice 1 is AO
  int inlet_channel = 0;    ///< AO channel of the inlet valve driver
  int exhaust_channel = 1;  ///< AO channel of the exhaust valve driver (not inlet_channel)
  int ao_range = 0;         ///< PCI-6221 AO range 0: +-10 V
  double v_closed = 0.0;    ///< V commanding a closed valve / 0 % duty
  double v_open = 5.0;      ///< V commanding an open valve / 100 % duty
  bool exhaust_complementary = true;  ///< exhaust = 100 - u (else kept closed)
  bool use_calibration = true;        ///< use the card's calibration polynomials when present

  /// True for an absolute device path, indices >= 0, distinct valve channels,
  /// v_min < v_max, finite gains, offsets and levels, pressure_gain != 0 and
  /// v_open != v_closed; otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
  /// Force (N) and pressure (Pa, in *pressure if not null) for a transducer voltage.
  double VoltsToForce(double volts, double* pressure = nullptr) const;
  /// Output levels (V) of the inlet and exhaust drivers for duty u (%, clamped to 0..100).
  void DutyToVolts(double u, double* inlet_v, double* exhaust_v) const;
  /// Output levels (V) of the safe state.
  void SafeStateVolts(SafeState s, double* inlet_v, double* exhaust_v) const;
  /// True when a voltage is outside the transducer window or not finite.
  bool VoltsOutOfRange(double volts) const;
};

/// True when libcomedi support was compiled in (PNEUMID_HAVE_COMEDI).
bool ComediAvailable();

/// IoBackend on a comedi data-acquisition card: reads the pressure transducer and
/// drives the inlet and exhaust valves of the paper's rig (see above).
class ComediBackend : public IoBackend {
 public:
  /// @throws InvalidArgument on an invalid configuration.
  explicit ComediBackend(ComediConfig config);
  ~ComediBackend() override;
  /// comedi_open, checks subdevices, channels and ranges, loads calibration.
  /// @throws DataError naming the device when it cannot be opened or does not fit the
  /// configuration; DataError when built without comedi.
  void Open(double period) override;
  IoStatus Read(Measurement* m) noexcept override;
  IoStatus Write(double u) noexcept override;
  IoStatus EnterSafeState(SafeState state) noexcept override;
  void Close() override;
  std::string Describe() const override;
  /// The paper's rig: the IPA in force mode (IpaActuator()).
  Actuator actuator() const override { return IpaActuator(); }
  const ComediConfig& config() const { return config_; }  ///< as given at construction

 private:
  struct Impl;
  IoStatus WriteVolts(double inlet_v, double exhaust_v) noexcept;
  ComediConfig config_;
  Impl* impl_ = nullptr;
};

}  // namespace pneumid
