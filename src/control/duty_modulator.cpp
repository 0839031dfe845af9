#include "pneumid/control/duty_modulator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

std::string InputGapsToString(const std::vector<InputGap>& gaps) {
  std::string s;
  for (const InputGap& g : gaps) s += (s.empty() ? "" : ",") + fmt::format("{:g}:{:g}", g.lo, g.hi);
  return s;
}

std::vector<InputGap> ParseInputGaps(const std::string& text) {
  std::vector<InputGap> gaps;
  if (text == "none") return gaps;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.find_first_not_of(" \t") == std::string::npos) continue;
    const auto colon = item.find(':');
    InputGap g;
    bool ok = colon != std::string::npos;
    if (ok) {
      try {
        std::size_t used_lo = 0, used_hi = 0;
        const std::string a = item.substr(0, colon), b = item.substr(colon + 1);
        g.lo = std::stod(a, &used_lo);
        g.hi = std::stod(b, &used_hi);
        ok = used_lo == a.size() && used_hi == b.size();
      } catch (const std::logic_error&) {
        ok = false;
      }
    }
    PNEUMID_CHECK(ok && std::isfinite(g.lo) && std::isfinite(g.hi) && g.lo < g.hi,
                  "input gaps: '{}' is not LO:HI with finite LO < HI (e.g. 0:15,85:100)", item);
    gaps.push_back(g);
  }
  (void)DutyModulator(gaps);  // checks overlaps
  return gaps;
}

DutyModulator::DutyModulator(std::vector<InputGap> gaps, double u_min, double u_max)
    : gaps_(std::move(gaps)), u_min_(u_min), u_max_(u_max) {
  PNEUMID_CHECK(!(u_min > u_max) && !std::isnan(u_min) && !std::isnan(u_max),
                "DutyModulator: needs u_min <= u_max, got {} and {}", u_min, u_max);
  std::sort(gaps_.begin(), gaps_.end(),
            [](const InputGap& a, const InputGap& b) { return a.lo < b.lo; });
  for (std::size_t i = 0; i < gaps_.size(); ++i) {
    const InputGap& g = gaps_[i];
    PNEUMID_CHECK(std::isfinite(g.lo) && std::isfinite(g.hi) && g.lo < g.hi,
                  "input gap ({}, {}): needs finite lo < hi", g.lo, g.hi);
    PNEUMID_CHECK(i == 0 || gaps_[i - 1].hi <= g.lo, "input gaps ({}, {}) and ({}, {}) overlap",
                  gaps_[i - 1].lo, gaps_[i - 1].hi, g.lo, g.hi);
    max_error_ = std::max(max_error_, g.hi - g.lo);
  }
}

double DutyModulator::Next(double v) {
  // A request at or beyond an end of the range carries nothing; inside it the
  // carried error may take w past an end, where the end is applied and the
  // rest is carried, so that the mean of the applied inputs follows a
  // request near an end without bias.
  if (v <= u_min_ || v >= u_max_) {  // saturated: the end, nothing carried
    error_ = 0.0;
    return std::clamp(v, u_min_, u_max_);
  }
  const double w = v + error_;
  double a = std::clamp(w, u_min_, u_max_);
  for (const InputGap& g : gaps_) {
    if (w > g.lo && w < g.hi) {
      a = (w - g.lo < g.hi - w) ? g.lo : g.hi;
      break;
    }
  }
  // A request held outside the gaps empties the error.
  error_ = std::clamp(w - a, -max_error_, max_error_);
  return a;
}

ModulatedController::ModulatedController(std::unique_ptr<Controller> inner,
                                         std::vector<InputGap> gaps, const InputLimits& limits)
    : inner_(std::move(inner)), modulator_(std::move(gaps), limits.u_min, limits.u_max) {
  PNEUMID_CHECK(inner_ != nullptr, "ModulatedController: the inner controller is null");
}

std::string ModulatedController::Describe() const {
  return inner_->Describe() + " with sigma-delta modulation over the input gaps " +
         InputGapsToString(modulator_.gaps());
}

void ModulatedController::DoReset(double u0, double y0) {
  inner_->Reset(u0, y0);
  modulator_.Reset();
  v_ = u0;
}

double ModulatedController::DoUpdate(double setpoint, double measurement) {
  v_ = inner_->Update(setpoint, measurement);
  return modulator_.Next(v_);
}

void ModulatedController::DoApplied(double u) {
  // The modulated input differs from the request by up to the widest gap by
  // design; a larger difference is a limit that cut the request itself.
  if (std::abs(u - v_) > modulator_.max_error()) inner_->Applied(u);
}

}  // namespace pneumid
