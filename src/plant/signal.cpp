// Experiment and set-point signals (see include/pneumid/plant/signal.hpp).
#include "pneumid/plant/signal.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <set>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/plant/prbs.hpp"

namespace pneumid {

Eigen::VectorXd Signal::Sample(double Ts, Eigen::Index n, double t0) const {
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(n >= 0, "number of samples must be non-negative, got n = {}", n);
  CheckSampleTime(Ts);
  Eigen::VectorXd v(n);
  for (Eigen::Index k = 0; k < n; ++k) v[k] = (*this)(t0 + static_cast<double>(k) * Ts);
  return v;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Edges are compared with a small tolerance so that t = k Ts lands on the
// intended side of an edge at t = at despite rounding of k * Ts.
constexpr double kEdgeTol = 1e-9;
bool Reached(double t, double edge) { return t >= edge - kEdgeTol * std::max(1.0, std::abs(edge)); }

std::string Num(double v) { return fmt::format("{:g}", v); }

/// Common post-processing: value = clamp(raw + offset, min, max).
struct Shaping {
  double offset = 0.0;
  double min = -kInf;
  double max = kInf;
  double Apply(double raw) const { return std::clamp(raw + offset, min, max); }
  std::string Suffix() const {
    std::string s;
    if (offset != 0.0) s += ",offset=" + Num(offset);
    if (min > -kInf) s += ",min=" + Num(min);
    if (max < kInf) s += ",max=" + Num(max);
    return s;
  }
};

/// value = clamp(raw + offset, min, max) from the offset=, min=, max= keys of a spec.
Shaping TakeShaping(Spec& p) {
  Shaping s;
  s.offset = p.Number("offset", 0.0);
  s.min = p.Bound("min", -kInf);
  s.max = p.Bound("max", kInf);
  PNEUMID_CHECK(s.min <= s.max, "{}: min = {} exceeds max = {}", p.Context(), s.min, s.max);
  return s;
}

/// floor(pos) with the edge tolerance of Reached(), as a double (exact for
/// |pos| < 2^53, where the caller may cast it to an integer).
double EdgeFloor(double pos) { return std::floor(pos + kEdgeTol * std::max(1.0, std::abs(pos))); }

// ---------------------------------------------------------------------------

class StepSignal final : public Signal {
 public:
  StepSignal(double from, double to, double at, Shaping s) : from_(from), to_(to), at_(at), s_(s) {}
  double operator()(double t) const override { return s_.Apply(Reached(t, at_) ? to_ : from_); }
  std::string ToString() const override {
    return "step:from=" + Num(from_) + ",to=" + Num(to_) + ",at=" + Num(at_) + s_.Suffix();
  }

 private:
  double from_, to_, at_;
  Shaping s_;
};

class StaircaseSignal final : public Signal {
 public:
  StaircaseSignal(std::vector<double> levels, double dwell, double at, Shaping s)
      : levels_(std::move(levels)), dwell_(dwell), at_(at), s_(s) {}
  double operator()(double t) const override {
    if (!Reached(t, at_)) return s_.Apply(levels_.front());
    // Index of the current level, with the same edge tolerance as Reached().
    // Clamped in double before the cast: (t - at) / dwell may exceed any integer.
    const double k =
        std::clamp(EdgeFloor((t - at_) / dwell_), 0.0, static_cast<double>(levels_.size() - 1));
    return s_.Apply(levels_[static_cast<std::size_t>(k)]);
  }
  std::string ToString() const override {
    std::string lv;
    for (std::size_t i = 0; i < levels_.size(); ++i) {
      if (i > 0) lv += ' ';
      lv += Num(levels_[i]);
    }
    return "staircase:levels=" + lv + ",dwell=" + Num(dwell_) + ",at=" + Num(at_) + s_.Suffix();
  }

 private:
  std::vector<double> levels_;
  double dwell_, at_;
  Shaping s_;
};

class PrbsSignal final : public Signal {
 public:
  PrbsSignal(double low, double high, int order, double clock, std::uint64_t seed, double at,
             Shaping s)
      : low_(low),
        high_(high),
        order_(order),
        clock_(clock),
        seed_(seed),
        at_(at),
        s_(s),
        gen_(order, seed) {}
  double operator()(double t) const override {
    if (!Reached(t, at_)) return s_.Apply(low_);
    const double pos = std::max(EdgeFloor((t - at_) / clock_), 0.0);
    PNEUMID_CHECK(pos < kMaxExactIndex,
                  "signal '{}': t = {} s is {:g} clock periods of {} s, beyond the exact "
                  "integers of a double (2^53): use a clock of at least {:g} s",
                  ToString(), t, pos, clock_, (t - at_) / kMaxExactIndex);
    const auto k = static_cast<std::uint64_t>(std::fmod(pos, static_cast<double>(gen_.period())));
    // The first bits are cached as they are generated; later ones (a period
    // of a high order is huge) are computed directly in O(order log k).
    if (k < kCachedBits) {
      while (bits_.size() <= k) bits_.push_back(gen_.Next());
      return s_.Apply(bits_[static_cast<std::size_t>(k)] ? high_ : low_);
    }
    return s_.Apply(MaxLengthSequenceBit(order_, seed_, k) ? high_ : low_);
  }
  std::string ToString() const override {
    return "prbs:low=" + Num(low_) + ",high=" + Num(high_) + ",order=" + std::to_string(order_) +
           ",clock=" + Num(clock_) + ",seed=" + std::to_string(seed_) + ",at=" + Num(at_) +
           s_.Suffix();
  }

 private:
  double low_, high_;
  int order_;
  static constexpr double kMaxExactIndex = 9007199254740992.0;  // 2^53
  static constexpr std::uint64_t kCachedBits = std::uint64_t{1} << 20;
  double clock_;
  std::uint64_t seed_;
  double at_;
  Shaping s_;
  mutable MaxLengthSequenceGenerator gen_;
  mutable std::vector<std::uint8_t> bits_;
};

// Multi-level pseudo-random signal: in clock period k (from `at` on) the
// level index is SplitMix64(seed + (k + 1) * 0x9E3779B97F4A7C15) mod levels
// [1], i.e. independent, uniformly distributed levels
//   low + (high - low) i / (levels - 1),  i = 0 .. levels - 1,
// computed directly for any k (no state, the same on every platform).
// [1] G. L. Steele, D. Lea, C. H. Flood, Fast splittable pseudorandom number
//     generators, OOPSLA 2014 (the SplitMix64 finalizer).
class PrbsLevelsSignal final : public Signal {
 public:
  PrbsLevelsSignal(double low, double high, int levels, double clock, std::uint64_t seed, double at,
                   Shaping s)
      : low_(low), high_(high), levels_(levels), clock_(clock), seed_(seed), at_(at), s_(s) {}
  double operator()(double t) const override {
    if (!Reached(t, at_)) return s_.Apply(low_);
    const double pos = std::max(EdgeFloor((t - at_) / clock_), 0.0);
    PNEUMID_CHECK(pos < 9007199254740992.0,
                  "signal '{}': t = {} s is {:g} clock periods of {} s, beyond the exact "
                  "integers of a double (2^53)",
                  ToString(), t, pos, clock_);
    return s_.Apply(Level(static_cast<std::uint64_t>(pos)));
  }
  std::string ToString() const override {
    return "prbs-levels:low=" + Num(low_) + ",high=" + Num(high_) +
           ",levels=" + std::to_string(levels_) + ",clock=" + Num(clock_) +
           ",seed=" + std::to_string(seed_) + ",at=" + Num(at_) + s_.Suffix();
  }

 private:
  double Level(std::uint64_t k) const {
    std::uint64_t z = seed_ + (k + 1) * 0x9E3779B97F4A7C15ULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    const auto i = static_cast<double>(z % static_cast<std::uint64_t>(levels_));
    return low_ + (high_ - low_) * i / static_cast<double>(levels_ - 1);
  }
  double low_, high_;
  int levels_;
  double clock_;
  std::uint64_t seed_;
  double at_;
  Shaping s_;
};

// Also the sine (f0 = f1, named "sine" in ToString, no end by default).
class ChirpSignal final : public Signal {
 public:
  ChirpSignal(double from, double to, double f0, double f1, double at, double duration, Shaping s,
              bool sine = false)
      : from_(from), to_(to), f0_(f0), f1_(f1), at_(at), duration_(duration), s_(s), sine_(sine) {}
  double operator()(double t) const override {
    const double mid = 0.5 * (from_ + to_);
    const double amp = 0.5 * (to_ - from_);
    const double tau = t - at_;
    if (tau < 0.0 || tau > duration_) return s_.Apply(mid);
    // Linear sweep: f(tau) = f0 + (f1 - f0) tau / D, phase = 2 pi int_0^tau f.
    const double phase =
        2.0 * std::numbers::pi * (f0_ * tau + 0.5 * (f1_ - f0_) * tau * tau / duration_);
    return s_.Apply(mid + amp * std::sin(phase));
  }
  void CheckSampleTime(double Ts) const override {
    const double f_max = std::max(f0_, f1_);
    PNEUMID_CHECK(f_max <= 0.5 / Ts,
                  "signal '{}': the {} reaches {} Hz, above the Nyquist frequency {} Hz of "
                  "the sample time Ts = {} s (it would be aliased): lower {} or Ts",
                  ToString(), sine_ ? "sine" : "chirp", f_max, 0.5 / Ts, Ts,
                  sine_ ? "the frequency" : "f0/f1");
  }
  std::string ToString() const override {
    if (sine_) {
      std::string text = "sine:from=" + Num(from_) + ",to=" + Num(to_) + ",frequency=" + Num(f0_) +
                         ",at=" + Num(at_);
      if (std::isfinite(duration_)) text += ",duration=" + Num(duration_);
      return text + s_.Suffix();
    }
    return "chirp:from=" + Num(from_) + ",to=" + Num(to_) + ",f0=" + Num(f0_) + ",f1=" + Num(f1_) +
           ",at=" + Num(at_) + ",duration=" + Num(duration_) + s_.Suffix();
  }

 private:
  double from_, to_, f0_, f1_, at_, duration_;
  Shaping s_;
  bool sine_;
};

class RampSignal final : public Signal {
 public:
  RampSignal(double from, double to, double at, double duration, Shaping s)
      : from_(from), to_(to), at_(at), duration_(duration), s_(s) {}
  double operator()(double t) const override {
    if (t <= at_) return s_.Apply(from_);
    if (t >= at_ + duration_) return s_.Apply(to_);
    return s_.Apply(from_ + (to_ - from_) * (t - at_) / duration_);
  }
  std::string ToString() const override {
    return "ramp:from=" + Num(from_) + ",to=" + Num(to_) + ",at=" + Num(at_) +
           ",duration=" + Num(duration_) + s_.Suffix();
  }

 private:
  double from_, to_, at_, duration_;
  Shaping s_;
};

/// Input read from a data file (CSV/MAT through LoadDataset): column `column`
/// against the time column `time_column`, held between samples.
class FileSignal final : public Signal {
 public:
  FileSignal(std::string path, std::string column, std::string time_column, Shaping s)
      : path_(std::move(path)),
        column_(std::move(column)),
        time_column_(std::move(time_column)),
        s_(s) {
    LoadOptions options;
    options.time_column = time_column_;
    options.input_columns = {column_};  // errors then speak of an input column
    options.output_columns = {};
    const Dataset data = LoadDataset(path_, options);
    if (data.size() < 1) throw DataError(fmt::format("{}: no samples", path_));
    time_.assign(data.time().data(), data.time().data() + data.size());
    const Eigen::VectorXd v = data.u(0);
    value_.assign(v.data(), v.data() + v.size());
  }
  double operator()(double t) const override {
    // Zero-order hold: the last sample at or before t (first value before the start).
    auto it =
        std::upper_bound(time_.begin(), time_.end(), t + kEdgeTol * std::max(1.0, std::abs(t)));
    if (it == time_.begin()) return s_.Apply(value_.front());
    return s_.Apply(value_[static_cast<std::size_t>(it - time_.begin() - 1)]);
  }
  std::string ToString() const override {
    return "file:" + path_ + ",col=" + column_ +
           (time_column_ == "t" ? "" : ",time=" + time_column_) + s_.Suffix();
  }

 private:
  std::string path_;
  std::string column_;
  std::string time_column_;
  Shaping s_;
  std::vector<double> time_;
  std::vector<double> value_;
};

}  // namespace

std::unique_ptr<Signal> ParseSignal(const std::string& spec_in) {
  const std::string_view trimmed = Trim(spec_in);
  PNEUMID_CHECK(!trimmed.empty(), "empty signal spec (expected e.g. 'step:from=0,to=1,at=1')");
  const std::string kind = ToLower(Trim(trimmed.substr(0, trimmed.find(':'))));
  static const std::set<std::string> kinds = {
      "step", "staircase", "multistep", "prbs", "prbs-levels", "chirp", "sine", "ramp", "file"};
  PNEUMID_CHECK(kinds.count(kind) != 0,
                "signal '{}': unknown kind '{}' (expected step, staircase, multistep, prbs, "
                "prbs-levels, chirp, sine, ramp or file)",
                trimmed, kind);
  Spec p("signal", trimmed, {.has_kind = true, .has_head = kind == "file"});
  const std::string& spec = p.text();

  std::unique_ptr<Signal> out;
  if (kind == "step") {
    double from = p.Number("from", 0.0);
    double to = p.Number("to");
    double at = p.Number("at", 0.0);
    Shaping s = TakeShaping(p);
    p.Finish();
    out = std::make_unique<StepSignal>(from, to, at, s);
  } else if (kind == "staircase" || kind == "multistep") {
    auto levels = p.List("levels");
    double dwell = p.Number("dwell");
    PNEUMID_CHECK(dwell > 0.0, "signal '{}': dwell must be positive, got {}", spec, dwell);
    double at = p.Number("at", 0.0);
    Shaping s = TakeShaping(p);
    p.Finish();
    out = std::make_unique<StaircaseSignal>(std::move(levels), dwell, at, s);
  } else if (kind == "prbs") {
    double low = p.Number("low", 0.0);
    double high = p.Number("high", 1.0);
    double order_d = p.Number("order", 7.0);
    PNEUMID_CHECK(order_d == std::floor(order_d) && order_d >= 2 && order_d <= 32,
                  "signal '{}': order must be an integer in 2..32, got {}", spec, order_d);
    int order = static_cast<int>(order_d);
    double clock = p.Number("clock");
    PNEUMID_CHECK(clock > 0.0, "signal '{}': clock must be positive, got {}", spec, clock);
    const double all_ones = std::ldexp(1.0, order) - 1.0;
    double seed_d = p.Number("seed", all_ones);
    PNEUMID_CHECK(seed_d == std::floor(seed_d) && seed_d >= 1 && seed_d <= all_ones,
                  "signal '{}': seed must be an integer in 1..2^order-1 = {}, got {}", spec,
                  all_ones, seed_d);
    double at = p.Number("at", 0.0);
    Shaping s = TakeShaping(p);
    p.Finish();
    out = std::make_unique<PrbsSignal>(low, high, order, clock, static_cast<std::uint64_t>(seed_d),
                                       at, s);
  } else if (kind == "prbs-levels") {
    double low = p.Number("low", 0.0);
    double high = p.Number("high", 1.0);
    double levels_d = p.Number("levels", 5.0);
    PNEUMID_CHECK(levels_d == std::floor(levels_d) && levels_d >= 2 && levels_d <= 1000,
                  "signal '{}': levels must be an integer in 2..1000, got {}", spec, levels_d);
    double clock = p.Number("clock");
    PNEUMID_CHECK(clock > 0.0, "signal '{}': clock must be positive, got {}", spec, clock);
    double seed_d = p.Number("seed", 1.0);
    PNEUMID_CHECK(seed_d == std::floor(seed_d) && seed_d >= 0 && seed_d <= 9007199254740992.0,
                  "signal '{}': seed must be an integer in 0..2^53, got {}", spec, seed_d);
    double at = p.Number("at", 0.0);
    Shaping s = TakeShaping(p);
    p.Finish();
    out = std::make_unique<PrbsLevelsSignal>(low, high, static_cast<int>(levels_d), clock,
                                             static_cast<std::uint64_t>(seed_d), at, s);
  } else if (kind == "chirp") {
    double from = p.Number("from");
    double to = p.Number("to");
    double f0 = p.Number("f0");
    double f1 = p.Number("f1");
    PNEUMID_CHECK(f0 >= 0.0 && f1 >= 0.0, "signal '{}': frequencies must be >= 0, got {} and {}",
                  spec, f0, f1);
    double at = p.Number("at", 0.0);
    double duration = p.Number("duration", 10.0);
    PNEUMID_CHECK(duration > 0.0, "signal '{}': duration must be positive, got {}", spec, duration);
    Shaping s = TakeShaping(p);
    p.Finish();
    out = std::make_unique<ChirpSignal>(from, to, f0, f1, at, duration, s);
  } else if (kind == "sine") {
    double from = p.Number("from");
    double to = p.Number("to");
    double frequency = p.Number("frequency");
    PNEUMID_CHECK(frequency > 0.0, "signal '{}': frequency must be positive, got {}", spec,
                  frequency);
    double at = p.Number("at", 0.0);
    double duration = p.Number("duration", std::numeric_limits<double>::infinity());
    PNEUMID_CHECK(duration > 0.0, "signal '{}': duration must be positive, got {}", spec, duration);
    Shaping s = TakeShaping(p);
    p.Finish();
    out = std::make_unique<ChirpSignal>(from, to, frequency, frequency, at, duration, s,
                                        /*sine=*/true);
  } else if (kind == "ramp") {
    double from = p.Number("from", 0.0);
    double to = p.Number("to");
    double at = p.Number("at", 0.0);
    double duration = p.Number("duration");
    PNEUMID_CHECK(duration > 0.0, "signal '{}': duration must be positive, got {}", spec, duration);
    Shaping s = TakeShaping(p);
    p.Finish();
    out = std::make_unique<RampSignal>(from, to, at, duration, s);
  } else {  // file
    PNEUMID_CHECK(!p.head().empty(), "signal '{}': file needs a path, e.g. 'file:data.csv,col=u'",
                  spec);
    std::string col = p.Text("col", "u");
    std::string time_col = p.Text("time", "t");
    Shaping s = TakeShaping(p);
    p.Finish();
    out = std::make_unique<FileSignal>(p.head(), col, time_col, s);
  }
  return out;
}

std::string SignalSyntaxHelp() {
  return R"(Signal specs (times in s, frequencies in Hz, amplitudes in input units):
  step:from=A,to=B,at=T                 A before T, B from T on (from defaults to 0, at to 0)
  staircase:levels=L0 L1 ...,dwell=D[,at=T]
                                        each level held D seconds from T on, the last held
                                        (alias multistep; levels separated by spaces, ';' or ',')
  prbs:low=A,high=B,order=N,clock=C[,seed=S][,at=T]
                                        maximal-length binary sequence from an N-bit LFSR
                                        (N = 2..32, period 2^N-1 clock periods of C seconds,
                                        seed = initial register 1..2^N-1, default all ones;
                                        same taps as scipy.signal.max_len_seq), repeated
  prbs-levels:low=A,high=B,levels=L,clock=C[,seed=S][,at=T]
                                        multi-level pseudo-random signal: in each clock
                                        period of C seconds one of L equally spaced levels
                                        from A to B (L = 2..1000, default 5), independent
                                        and uniformly drawn from seed S (default 1; the same
                                        on every run and platform); A before T
  chirp:from=A,to=B,f0=F0,f1=F1[,at=T][,duration=D]
                                        sine between A and B, frequency swept linearly from
                                        F0 to F1 over D seconds (default 10), (A+B)/2 outside
  sine:from=A,to=B,frequency=F[,at=T][,duration=D]
                                        sine between A and B of F Hz from T on, starting at
                                        (A+B)/2 upwards; (A+B)/2 before T and after D seconds
                                        (default: no end)
  ramp:from=A,to=B,at=T,duration=D      A until T, linear to B over D seconds, then B
  file:PATH[,col=NAME][,time=NAME]     column (MAT: variable) NAME (default u) of a CSV or
                                        .mat data file against its time column (default t),
                                        held between samples
Every kind also takes offset=O, min=LO, max=HI: value = clamp(signal + O, LO, HI).
Example: --input step:from=0.61,to=82,at=1.0
)";
}

}  // namespace pneumid
