// The steady-state input-output map of a plant from a staircase (or a slow
// ramp) experiment, as a monotone piecewise-linear StaticMap
// (models/static_map.hpp). Method `static-map` of `pneumid identify`.
//
// Staircase ([1] sec. 13.2, static gain from steady states):
//   1. segments of constant input: runs of samples whose input differs from
//      the run's first by at most `level_tolerance`; runs shorter than
//      `min_segment_duration` (not settled: PRBS bits, pulses) are skipped;
//   2. the steady output of a segment is the mean of y over its last
//      `settle_fraction` (the first part is the transient);
//   3. segments at the same level (within `level_tolerance`) are merged, the
//      means weighted by their sample counts: levels u_i, values ybar_i, weights w_i;
//   4. monotone by the pool-adjacent-violators algorithm (PAVA, [2]): the
//      weighted least-squares non-decreasing (or non-increasing, by the sign
//      of the least-squares slope of ybar against u) sequence closest to ybar;
//      pooled levels share one value, so a dead zone or a saturation measured
//      with noise comes out flat;
//   5. optional smoothing: `smoothing_passes` passes of the weights
//      [1 2 1]/4 over the interior values (ends kept), then PAVA again.
// The knots are the levels u_i, the values the result of 4-5.
//
// Slow ramp (quasi-static: the ramp must be slow against the plant's time
// constants): the input range is cut into `ramp_bins` equal bins; each
// non-empty bin gives the knot (mean u, mean y), then steps 4-5.
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
// [2] M. Ayer, H. D. Brunk, G. M. Ewing, W. T. Reid, E. Silverman, An empirical
//     distribution function for sampling with incomplete information, Ann.
//     Math. Statist. 26 (1955) 641-647; R. E. Barlow et al., Statistical
//     Inference under Order Restrictions, Wiley, 1972, ch. 1.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/common/termination.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid {

/// Which experiment the data are.
enum class StaticMapSource {
  kAuto,       ///< "auto": staircase when >= 2 settled levels, else a monotone ramp
  kStaircase,  ///< "staircase": segments of constant input
  kRamp,       ///< "ramp": a slow ramp, binned
};
/// "auto", "staircase" or "ramp".
std::string ToString(StaticMapSource s);
/// Inverse of ToString. @throws InvalidArgument listing the valid names.
StaticMapSource StaticMapSourceFromString(const std::string& name);

/// How FitStaticMap finds the steady states and shapes the map.
struct StaticMapFitOptions {
  StaticMapSource source = StaticMapSource::kAuto;  ///< kind of experiment (default: detect)
  /// Fraction of each segment, at its end, averaged for the steady output;
  /// in (0, 1]. Default 0.5.
  double settle_fraction = 0.5;
  /// Constant-input segments shorter than this (s) are skipped; >= 0.
  /// Default 1 s.
  double min_segment_duration = 1.0;
  /// Input values within this (input units) of each other are one level;
  /// >= 0. Default 1e-6.
  double level_tolerance = 1e-6;
  /// Make the map monotone (PAVA); default true.
  bool monotone = true;
  /// Passes of the [1 2 1]/4 smoother (>= 0, default 0).
  int smoothing_passes = 0;
  /// Bins of a ramp (>= 2, default 20).
  int ramp_bins = 20;
  /// How the map extrapolates (default clamp: saturated beyond the levels).
  StaticMapExtrapolation extrapolation = StaticMapExtrapolation::kClamp;
  /// True when settle_fraction is in (0, 1], min_segment_duration and level_tolerance are
  /// finite and >= 0, smoothing_passes >= 0 and ramp_bins >= 2; otherwise false with the
  /// reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// What FitStaticMap used and how much monotonicity and smoothing changed the levels.
struct StaticMapFitSummary {
  StaticMapSource source = StaticMapSource::kStaircase;  ///< what was used
  int segments_used = 0;     ///< settled segments (staircase) or filled bins (ramp)
  int segments_skipped = 0;  ///< constant-input runs too short to settle
  int levels_pooled = 0;     ///< levels merged by PAVA into a neighbour's value
  /// Largest |value - level mean| that PAVA and smoothing introduced (output units).
  double max_adjustment = 0.0;
  Termination termination = Termination::kConvergence;  ///< kConvergence (failures throw)
  std::string message;  ///< e.g. "11 knots from 11 settled segment(s), ..." with the map
  /// One line: "static-map convergence: staircase, 11 levels, 2 pooled (max change 0.8)".
  std::string BriefReport() const;
};

/// Fitted static map y = f(u) and the measured steady states it goes through.
struct StaticMapFitResult {
  /// Piecewise linear through (level_u, adjusted level_y), extrapolated as the options say.
  StaticMap map;
  /// The measured steady states before PAVA / smoothing, with their weights
  /// (samples averaged), sorted by level: level_u the input levels (input units).
  std::vector<double> level_u, level_y, weight;  ///< samples averaged for each level
  /// @var level_y
  /// Mean steady output at each input level (output units), before PAVA / smoothing.
  StaticMapFitSummary summary;  ///< source used, segments, pooling and message
};

/// Fits the map from input u and output y sampled every Ts seconds.
/// @throws InvalidArgument for invalid options, sizes that differ, fewer than
///         2 samples, non-finite values, or data from which no map follows:
///         an input that never leaves one operating point (naming the level
///         and the input range), fewer than 2 settled levels of a staircase
///         (naming the levels and segment lengths found), a ramp source on an
///         input that is not monotone.
StaticMapFitResult FitStaticMap(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                const StaticMapFitOptions& options = {});
/// As above for input column `input` and output column `output` of `data`
/// (uniformly sampled).
StaticMapFitResult FitStaticMap(const Dataset& data, int input = 0, int output = 0,
                                const StaticMapFitOptions& options = {});

/// Knots of a piecewise-linear map of u placed where the data are (the input
/// map of hammerstein, hw and affine-narx):
///  - num_knots == 0 (automatic): when the input dwells on few levels (a
///    staircase or a multi-level signal: at least 90 % of the samples on at
///    most `max_levels` values, each held for 3 or more samples), the knots are
///    those levels, plus min u / max u where samples lie beyond them (ramps
///    between levels); otherwise 11 knots at the quantiles 0, 0.1, .., 1 of u
///    (equal values merged), so that every tent holds about as many samples;
///  - num_knots >= 2: that many spread evenly over [min u, max u].
/// @throws InvalidArgument for an empty or non-finite u, num_knots 1 or < 0.
std::vector<double> PlaceMapKnots(const Eigen::VectorXd& u, int num_knots = 0, int max_levels = 60);

/// A knot interval of a map with no data inside whose value changes much
/// more steeply than on the intervals beside it, or bends away from their
/// lines: the data leave the map undetermined there (a jump may lie anywhere
/// between the two knots).
struct MapGap {
  /// Lower knot of the gap (input units).
  double u_lo = 0.0, u_hi = 0.0;  ///< the knots around the gap
  double change = 0.0;            ///< f(u_hi) - f(u_lo)
  std::string Describe() const;   ///< "between u = 85 and 95 the map changes by 58 (...)"
};

/// Whether the input value u visits the open interval (lo, hi) of a map gap:
/// it lies inside by more than 1 % of the interval's width from either end,
/// so a sample at one of the visited levels that bound the gap (or within
/// its rounding or noise) does not count. FindMapGaps, ExtrapolationWarnings
/// and the ranking of IdentifyModels share this test.
bool VisitsMapGap(double u, double lo, double hi);

/// The gaps of `map` fitted on input u: intervals (c_j, c_j+1) that hold no
/// sample of u strictly inside (VisitsMapGap: beyond 1 % of the interval from either knot),
/// whose change |f(c_j+1) - f(c_j)| is at least 5 % of the map's range, and
/// either whose slope is at least 2.5 times the steeper of the neighbouring
/// intervals' slopes (a jump), or where a flatter neighbouring interval's
/// line, extended to the interval's middle, misses the chord there by 40 % of
/// the interval's change or more (a flat neighbour misses by half of it, a
/// parabola through three equally spaced knots by a third): a bend the
/// interpolation cannot place, e.g. levels 70 and 86 % on the default twin,
/// around its exhaust's jump at 85-86 %, whose slope is 2.0 times that of
/// 62-70 %, or 14 and 24 %, around the inlet's jump at 14-15 %), or that is
/// wide (at least twice the knots' median spacing and 15 % of their span)
/// with a change of 10 % of the range or more: levels 24 and 56 % leave the
/// default twin's map bent by 6 N between them, levels 73 and 91 % its jump;
/// or whose change is a third of the range or more and at least twice as
/// steep as the steeper neighbour (levels 79 and 93 % hold the default
/// twin's exhaust jump and 40 % of its range, 2.3 times as steep as 66-79 %).
std::vector<MapGap> FindMapGaps(const StaticMap& map, const Eigen::VectorXd& u);

/// The weighted least-squares non-decreasing (`increasing`) or non-increasing
/// sequence closest to `values` (PAVA [2]), weights > 0.
/// @throws InvalidArgument for sizes that differ or a weight <= 0.
std::vector<double> PoolAdjacentViolators(const std::vector<double>& values,
                                          const std::vector<double>& weights, bool increasing);

}  // namespace pneumid
