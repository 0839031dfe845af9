#include "pneumid/realtime/comedi_backend.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

#ifdef PNEUMID_HAVE_COMEDI
#include <comedilib.h>
#endif

namespace pneumid {

namespace {
constexpr EnumName<AnalogReference> kAnalogReferenceNames[] = {
    {AnalogReference::kGround, "ground"},
    {AnalogReference::kCommon, "common"},
    {AnalogReference::kDiff, "diff"},
    {AnalogReference::kOther, "other"},
};
}  // namespace

const char* ToString(AnalogReference v) { return EnumToString(kAnalogReferenceNames, v).data(); }

AnalogReference AnalogReferenceFromString(const std::string& name) {
  return EnumFromString(kAnalogReferenceNames, name, "analog reference");
}

bool ComediConfig::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (device.empty() || device[0] != '/')
    return fail(fmt::format("comedi device must be an absolute path, got '{}'", device));
  for (auto [name, v] : {std::pair{"ai_subdevice", ai_subdevice},
                         {"ai_channel", ai_channel},
                         {"ai_range", ai_range},
                         {"ao_subdevice", ao_subdevice},
                         {"inlet_channel", inlet_channel},
                         {"exhaust_channel", exhaust_channel},
                         {"ao_range", ao_range}})
    if (v < 0) return fail(fmt::format("comedi {} must be >= 0, got {}", name, v));
  if (inlet_channel == exhaust_channel)
    return fail(fmt::format("inlet and exhaust valves need different channels, both are {}",
                            inlet_channel));
  if (!(v_min < v_max))
    return fail(fmt::format("need v_min < v_max, got [{}, {}] V", v_min, v_max));
  for (auto [name, v] : {std::pair{"pressure_gain", pressure_gain},
                         {"pressure_offset", pressure_offset},
                         {"force_gain", force_gain},
                         {"force_offset", force_offset},
                         {"v_closed", v_closed},
                         {"v_open", v_open}})
    if (!std::isfinite(v)) return fail(fmt::format("comedi {} must be finite, got {}", name, v));
  if (pressure_gain == 0.0) return fail("comedi pressure_gain must not be 0");
  if (v_open == v_closed) return fail(fmt::format("v_open and v_closed are both {} V", v_open));
  return true;
}

double ComediConfig::VoltsToForce(double volts, double* pressure) const {
  const double p = pressure_gain * volts + pressure_offset;
  if (pressure) *pressure = p;
  return force_gain * p + force_offset;
}

void ComediConfig::DutyToVolts(double u, double* inlet_v, double* exhaust_v) const {
  const double d = std::clamp(std::isfinite(u) ? u : 0.0, 0.0, 100.0) / 100.0;
  *inlet_v = v_closed + d * (v_open - v_closed);
  *exhaust_v = exhaust_complementary ? v_closed + (1.0 - d) * (v_open - v_closed) : v_closed;
}

void ComediConfig::SafeStateVolts(SafeState s, double* inlet_v, double* exhaust_v) const {
  *inlet_v = v_closed;
  *exhaust_v = s == SafeState::kRelease ? v_open : v_closed;
}

bool ComediConfig::VoltsOutOfRange(double volts) const {
  return !std::isfinite(volts) || volts < v_min || volts > v_max;
}

#ifdef PNEUMID_HAVE_COMEDI
bool ComediAvailable() { return true; }

struct ComediBackend::Impl {
  comedi_t* dev = nullptr;
  lsampl_t ai_maxdata = 0, ao_maxdata = 0;
  comedi_range* ai_range = nullptr;
  comedi_range* ao_range = nullptr;
  comedi_polynomial_t ai_poly{}, ao_in_poly{}, ao_ex_poly{};
  bool ai_cal = false, ao_in_cal = false, ao_ex_cal = false;
  std::string calibration = "nominal range (no calibration)";
};

ComediBackend::ComediBackend(ComediConfig config) : config_(std::move(config)) {
  std::string error;
  PNEUMID_CHECK(config_.IsValid(&error), "invalid comedi configuration: {}", error);
}

ComediBackend::~ComediBackend() {
  if (impl_ && impl_->dev) comedi_close(impl_->dev);
  delete impl_;
}

void ComediBackend::Open(double) {
  Close();
  impl_ = new Impl;
  const auto& c = config_;
  impl_->dev = comedi_open(c.device.c_str());
  if (!impl_->dev)
    throw DataError(fmt::format("{}: cannot open comedi device: {}", c.device,
                                comedi_strerror(comedi_errno())));
  comedi_t* d = impl_->dev;
  auto check_channel = [&](int subdev, int chan, int range, const char* what) {
    const int nch = comedi_get_n_channels(d, subdev);
    if (nch < 0)
      throw DataError(fmt::format("{}: {} subdevice {} does not exist", c.device, what, subdev));
    if (chan >= nch)
      throw DataError(fmt::format("{}: {} channel {} out of range (subdevice {} has {})", c.device,
                                  what, chan, subdev, nch));
    const int nr = comedi_get_n_ranges(d, subdev, chan);
    if (range >= nr)
      throw DataError(
          fmt::format("{}: {} range {} out of range (channel has {})", c.device, what, range, nr));
  };
  check_channel(c.ai_subdevice, c.ai_channel, c.ai_range, "analog input");
  check_channel(c.ao_subdevice, c.inlet_channel, c.ao_range, "inlet valve output");
  check_channel(c.ao_subdevice, c.exhaust_channel, c.ao_range, "exhaust valve output");
  impl_->ai_maxdata = comedi_get_maxdata(d, c.ai_subdevice, c.ai_channel);
  impl_->ao_maxdata = comedi_get_maxdata(d, c.ao_subdevice, c.inlet_channel);
  impl_->ai_range = comedi_get_range(d, c.ai_subdevice, c.ai_channel, c.ai_range);
  impl_->ao_range = comedi_get_range(d, c.ao_subdevice, c.inlet_channel, c.ao_range);
  if (c.use_calibration) {
    const int flags = comedi_get_subdevice_flags(d, c.ai_subdevice);
    if (flags >= 0 && (flags & SDF_SOFT_CALIBRATED)) {
      char* path = comedi_get_default_calibration_path(d);
      comedi_calibration_t* cal = path ? comedi_parse_calibration_file(path) : nullptr;
      if (cal) {
        impl_->ai_cal = comedi_get_softcal_converter(c.ai_subdevice, c.ai_channel, c.ai_range,
                                                     COMEDI_TO_PHYSICAL, cal, &impl_->ai_poly) == 0;
        impl_->ao_in_cal =
            comedi_get_softcal_converter(c.ao_subdevice, c.inlet_channel, c.ao_range,
                                         COMEDI_FROM_PHYSICAL, cal, &impl_->ao_in_poly) == 0;
        impl_->ao_ex_cal =
            comedi_get_softcal_converter(c.ao_subdevice, c.exhaust_channel, c.ao_range,
                                         COMEDI_FROM_PHYSICAL, cal, &impl_->ao_ex_poly) == 0;
        comedi_cleanup_calibration(cal);
        impl_->calibration = fmt::format("software calibration from {}", path);
      } else {
        impl_->calibration =
            fmt::format("nominal range (no calibration file{}; run comedi_soft_calibrate)",
                        path ? fmt::format(" at {}", path) : std::string());
      }
      free(path);
    } else {
      impl_->ai_cal = comedi_get_hardcal_converter(d, c.ai_subdevice, c.ai_channel, c.ai_range,
                                                   COMEDI_TO_PHYSICAL, &impl_->ai_poly) == 0;
      impl_->ao_in_cal =
          comedi_get_hardcal_converter(d, c.ao_subdevice, c.inlet_channel, c.ao_range,
                                       COMEDI_FROM_PHYSICAL, &impl_->ao_in_poly) == 0;
      impl_->ao_ex_cal =
          comedi_get_hardcal_converter(d, c.ao_subdevice, c.exhaust_channel, c.ao_range,
                                       COMEDI_FROM_PHYSICAL, &impl_->ao_ex_poly) == 0;
      if (impl_->ai_cal) impl_->calibration = "hardware calibration";
    }
  }
  comedi_set_global_oor_behavior(COMEDI_OOR_NAN);
}

IoStatus ComediBackend::Read(Measurement* m) noexcept {
  if (!impl_ || !impl_->dev) return IoStatus::kError;
  const auto& c = config_;
  lsampl_t raw = 0;
  if (comedi_data_read(impl_->dev, c.ai_subdevice, c.ai_channel, c.ai_range,
                       static_cast<unsigned>(c.ai_aref), &raw) < 0)
    return IoStatus::kError;
  const double volts = impl_->ai_cal ? comedi_to_physical(raw, &impl_->ai_poly)
                                     : comedi_to_phys(raw, impl_->ai_range, impl_->ai_maxdata);
  double p = 0.0;
  m->y = c.VoltsToForce(volts, &p);
  m->aux = p;
  if (raw == 0 || raw >= impl_->ai_maxdata || c.VoltsOutOfRange(volts))
    return IoStatus::kOutOfRange;
  return IoStatus::kOk;
}

IoStatus ComediBackend::Write(double u) noexcept {
  if (!impl_ || !impl_->dev) return IoStatus::kError;
  double vi = 0.0, ve = 0.0;
  config_.DutyToVolts(u, &vi, &ve);
  return WriteVolts(vi, ve);
}

IoStatus ComediBackend::EnterSafeState(SafeState s) noexcept {
  if (!impl_ || !impl_->dev) return IoStatus::kError;
  double vi = 0.0, ve = 0.0;
  config_.SafeStateVolts(s, &vi, &ve);
  return WriteVolts(vi, ve);
}

IoStatus ComediBackend::WriteVolts(double inlet_v, double exhaust_v) noexcept {
  comedi_t* d = impl_->dev;
  const ComediConfig& c = config_;
  const Impl* impl = impl_;
  auto to_raw = [&](double v, bool cal, const comedi_polynomial_t& poly) {
    return cal ? comedi_from_physical(v, &poly)
               : comedi_from_phys(v, impl->ao_range, impl->ao_maxdata);
  };
  const lsampl_t ri = to_raw(inlet_v, impl->ao_in_cal, impl->ao_in_poly);
  const lsampl_t re = to_raw(exhaust_v, impl->ao_ex_cal, impl->ao_ex_poly);
  const int a = comedi_data_write(d, c.ao_subdevice, c.inlet_channel, c.ao_range, AREF_GROUND, ri);
  const int b =
      comedi_data_write(d, c.ao_subdevice, c.exhaust_channel, c.ao_range, AREF_GROUND, re);
  return (a < 0 || b < 0) ? IoStatus::kError : IoStatus::kOk;
}

void ComediBackend::Close() {
  if (impl_ && impl_->dev) comedi_close(impl_->dev);
  delete impl_;
  impl_ = nullptr;
}

std::string ComediBackend::Describe() const {
  return fmt::format("comedi:{} (AI {}/{} range {} {}, AO {}/{},{} range {}{})", config_.device,
                     config_.ai_subdevice, config_.ai_channel, config_.ai_range,
                     ToString(config_.ai_aref), config_.ao_subdevice, config_.inlet_channel,
                     config_.exhaust_channel, config_.ao_range,
                     impl_ ? ", " + impl_->calibration : std::string());
}

#else  // !PNEUMID_HAVE_COMEDI

bool ComediAvailable() { return false; }
struct ComediBackend::Impl {};
ComediBackend::ComediBackend(ComediConfig config) : config_(std::move(config)) {
  std::string error;
  PNEUMID_CHECK(config_.IsValid(&error), "invalid comedi configuration: {}", error);
}
ComediBackend::~ComediBackend() = default;
void ComediBackend::Open(double) {
  throw DataError(
      fmt::format("{}: this pneumid was built without libcomedi (install "
                  "libcomedi-dev and reconfigure)",
                  config_.device));
}
IoStatus ComediBackend::Read(Measurement*) noexcept { return IoStatus::kError; }
IoStatus ComediBackend::Write(double) noexcept { return IoStatus::kError; }
IoStatus ComediBackend::EnterSafeState(SafeState) noexcept { return IoStatus::kError; }
IoStatus ComediBackend::WriteVolts(double, double) noexcept { return IoStatus::kError; }
void ComediBackend::Close() {}
std::string ComediBackend::Describe() const { return "comedi:" + config_.device + " (not built)"; }

#endif

}  // namespace pneumid
