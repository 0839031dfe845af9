// Commissioning: from a plant to a verified controller in one call
// (`pneumid commission`). The stages, all on the plant itself:
//
//   1. probe      the plant rests at the lowest input, then one step to the middle
//                 of the input range, extended in 0.5 s chunks until the
//                 means of two successive chunks agree to 0.5 % of the change:
//                 the static gain K, time constant tau and dead time theta by
//                 the two-point method (Smith 1972: tau = 1.5 (t63 - t28),
//                 theta = t63 - tau); a plant whose output does
//                 not move is "not responding", one whose output does not settle
//                 within a quarter of the budget is integrating or unstable.
//   2. sweep      the highest input, held for theta + 6 tau: with the rest level,
//                 the reachable output range. A requested range outside it is an
//                 error that names the measured range.
//   3. excitation a multi-level sequence over the inputs that cover the asked
//                 range (levels from the three measured points, shuffled, so the
//                 output moves both ways by large and small steps), dwell
//                 theta + 4 tau (at least 10 samples), filling what the
//                 budget leaves after the verification runs (stage 6: the
//                 first design's and up to `retunes` redesigns', as many as
//                 cost the excitation at most a quarter of what one run
//                 leaves it; each with the rest before it on a plant that
//                 cannot be reset), and
//                 at least 11 levels (a budget too short for them is an
//                 error that says what the time scale needs); a
//                 second sequence on levels between the first's (30 % of the
//                 time) is held out for validation.
//   4. identify   the candidate methods (linear and nonlinear) on the first
//                 sequence, ranked by their simulation fit on the held-out one
//                 (IdentifyModels; the polynomial models' input delay nk from
//                 the probe's dead time, floor(theta / Ts), at least 1); the
//                 model is the best-ranked one a
//                 controller can be built from.
//   5. design     the controller tuned to the specification (rule "auto",
//                 auto_tuning.hpp), behind the model's input map when it has one.
//                 An MPC, DMC or GPC aims at 1.25 times the response time of the
//                 fastest robust design (whose overshoot on the model is at
//                 the specification: on the plant's small steps it overshoots).
//                 When the actuator has input gaps (a PWM valve's minimum
//                 pulse: IPA duties in (0, 15) and (85, 100) %), the input is
//                 sigma-delta modulated across them (duty_modulator.hpp), in
//                 the experiment and in the controller alike, so the models
//                 see the actuator as the controller will drive it.
//   6. verify     a staircase across the range in both directions (levels at
//                 0, 25, 60, 85, 100, 88, 70, 78, 35, 10, 18 and 0 % of the
//                 range: three small steps among the large ones), dwell
//                 max(1 s, 2 x the settling specification)) and a load step
//                 (-8 % of the range) half-way through the last level, closed
//                 loop on the plant. Pass: the worst step's overshoot within
//                 the specification, every step settled within the settling
//                 specification, ripple at most 2 % of the set-point (or
//                 twice the output's peak to peak at rest, the sensor's
//                 noise, when that is larger) and
//                 |steady-state error| at most 0.5 % of the range at every
//                 level. On an overshoot failure the design is repeated with a
//                 less aggressive setting (up to `retunes` times; when none
//                 passes, the one with the fewest failures is kept). A passing
//                 design within 80 % of the specified overshoot is softened
//                 too; when every softer one fails and the kept design's
//                 overshoot beyond half the ripple is within that margin, the
//                 design at aggressiveness 1 is tried once and kept if it
//                 passes with its overshoot beyond half the ripple within
//                 the margin and no more than 5 % of the specification above
//                 the kept one's, and an IAE at least 5 % lower. Once a
//                 design has passed, another is verified only when its run
//                 fits in what is left of the budget, and softening stops
//                 when a softer design fails on more than its overshoot
//                 (settling, steady-state error). What limits
//                 the loop (saturation, dead time, model error, ripple) is
//                 stated with what to try.
//
// Integrating plants (the IPA in position mode: the piston moves while the
// valves are open and stays where it is when they are closed) have no steady
// state to probe; their stages are:
//
//   1. rest       0.5 s at input 0 (valves closed): the sensor's noise.
//   2. pulses     eight pulses at 20, 30, 45 and 60 % of the input range, two
//                 each, each toward the middle of the range and followed by a
//                 rest; the first lasts 0.05 s, the next are timed to move
//                 about 15 % of the range (at most twice or half the last
//                 length: the first pulses also spend time breaking away;
//                 a pulse ends early when the output leaves the range by
//                 5 %). The velocity gain Ki is the least-
//                 squares slope of v = Ki u + c sign(u) over the pulses (v =
//                 displacement / pulse time); the model is Ki / s.
//   3. design     a PD on y with the velocity feed-forward 1/Ki + Kc Td
//                 (controller_factory.hpp): for a closed-loop time constant
//                 tau = settling / 8, Kc Ki = 3 / tau and Kc Ki Td = 1
//                 (docs/position.md); the range served is the output range of
//                 the actuator less 10 % at each end, or the one asked for.
//   4. verify     as above without the small steps (levels at 0, 25, 60, 85,
//                 100, 70, 35, 10 and 0 %), with |steady-state error| at most
//                 0.125 % of the range (0.1 mm over 80 mm); a design that overshoots or
//                 cycles is repeated with tau x 1.5.
//
// Plant time is counted and reported for every stage. A stop request (the
// `stop` flag, set by SIGINT) or an output beyond the safety limits ends the
// experiment with the plant at its lowest input (the IPA's vented state) and
// the data recorded so far kept in the result.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pneumid/common/termination.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/plant/plant_factory.hpp"

namespace pneumid {

/// Settings of Commission (defaults: the IPA's force loop).
struct CommissionOptions {
  /// Output range the controller must serve (output units); NaN = the
  /// reachable range measured by the sweep, less 5 % at each end.
  double range_min = std::numeric_limits<double>::quiet_NaN();
  double range_max = std::numeric_limits<double>::quiet_NaN();  ///< upper end of that range
  /// Plant time in s the experiment (probe, sweep and excitation) and the
  /// verification runs may take together: the excitation leaves room for
  /// the first design's run and up to `retunes` redesigns' runs (as many as
  /// cost it at most a quarter of what one run leaves it); once a design has
  /// passed, further runs are made only within the budget, and only while no
  /// design has passed do they come on top of it. A budget that cannot hold
  /// them keeps the excitation's 11 levels, and the runs come on top of it.
  double budget = 120.0;
  /// Input limits (input units); NaN = the plant's physical range (IPA 0..100 %).
  double u_min = std::numeric_limits<double>::quiet_NaN();
  double u_max = std::numeric_limits<double>::quiet_NaN();  ///< highest input (NaN = the plant's)
  /// Output safety limits: leaving them stops the experiment (infinite = none).
  double y_min = -std::numeric_limits<double>::infinity();
  double y_max = std::numeric_limits<double>::infinity();  ///< highest output allowed
  /// Controller to design: mpc, dmc, gpc or pid.
  std::string controller = "mpc";
  /// Specification: worst-step overshoot in %, settling time (2 % band or the
  /// measured ripple) in s.
  double overshoot = 5.0;
  double settling = 0.5;  ///< settling time of the specification in s
  /// Aggressiveness of the first design (auto_tuning.hpp, 0..1).
  double aggressiveness = 0.5;
  /// The actuator's description (input range, input gaps, channels); unset =
  /// PlantActuator(plant). Set it for a plant behind an I/O backend
  /// (realtime/io_plant.hpp: IoPlant::actuator()).
  std::optional<Actuator> actuator;
  /// Modulate the input across the actuator's input gaps (Actuator::input_gaps,
  /// duty_modulator.hpp) in the experiment and in the controller, so that the
  /// outputs between the gaps' ends are reachable without a limit cycle.
  bool modulate = true;
  /// Redesigns with a less aggressive setting after an overshoot failure.
  int retunes = 2;
  /// Candidate identification methods (identify.hpp names).
  std::vector<std::string> methods = {"arx", "oe", "n4sid", "hammerstein", "affine-narx"};
  /// Dwell of the verification staircase in s; NaN = max(1 s, 2 x settling).
  double verification_dwell = std::numeric_limits<double>::quiet_NaN();
  /// Load step of the verification in output units; NaN = -8 % of the range.
  double load_step = std::numeric_limits<double>::quiet_NaN();
  /// Directory the model file is written to (the controller refers to it as
  /// DIR/models.json\#METHOD); must exist.
  std::string directory = ".";
  /// Seed of the level order of the excitation.
  std::uint64_t seed = 1;
  /// Called with the stage ("probe", "sweep", "excitation", "identify",
  /// "design", "verify") and the fraction of that stage done (0..1).
  std::function<void(const std::string& stage, double fraction)> progress;
  /// When set and true, the experiment stops at the next sample (plant left
  /// at u_min, data kept, termination kStopped).
  const std::atomic<bool>* stop = nullptr;
  /// True when the settings are consistent; else false with the reason.
  bool IsValid(std::string* error) const;
};

/// What the experiment measured.
struct CommissionExperiment {
  Dataset data;           ///< the whole record (t, u, y), every stage in order
  Dataset estimation;     ///< the excitation the models are estimated on
  Dataset validation;     ///< the held-out excitation they are ranked on
  double duration = 0.0;  ///< plant time of the experiment in s
  double gain = std::numeric_limits<double>::quiet_NaN();           ///< probe step: K
  double time_constant = std::numeric_limits<double>::quiet_NaN();  ///< probe step: tau in s
  double dead_time = std::numeric_limits<double>::quiet_NaN();      ///< probe step: theta in s
  double reachable_min = std::numeric_limits<double>::quiet_NaN();  ///< output at u_min
  double reachable_max = std::numeric_limits<double>::quiet_NaN();  ///< output at u_max
  double range_min = std::numeric_limits<double>::quiet_NaN();      ///< range served
  double range_max = std::numeric_limits<double>::quiet_NaN();      ///< its upper end
  /// Peak-to-peak output at rest (the last 80 % of the first second): the
  /// sensor's noise, the floor of the ripple criterion.
  double noise_peak_to_peak = 0.0;
  /// Standard deviation of the output at rest (the same samples): the MPC's
  /// Kalman filter takes its square as the measurement noise variance.
  double noise_std = 0.0;
  double dwell = 0.0;                     ///< s per excitation level
  std::vector<double> estimation_levels;  ///< inputs of the estimation sequence
  std::vector<double> validation_levels;  ///< inputs of the held-out sequence
  /// Steady output of each excitation level (the mean of the last quarter of
  /// its hold), estimation then held-out levels, in the order held.
  std::vector<double> level_outputs;
  /// Ripple of each level (same order): the peak-to-peak of the last quarter
  /// of its hold about its linear trend. Inside a valve's gap the modulation
  /// ripples and wanders by itself; the verification allows 1.25 times the
  /// larger ripple of the two levels whose outputs bracket the set-point, in
  /// its ripple criterion and as the least half-width of its settling band
  /// (ClosedLoopOptions::settling_band_floor).
  std::vector<double> level_ripples;
  /// {duration, samples, probe, sweep, range, noise_peak_to_peak, noise_std, dwell,
  /// estimation_levels, validation_levels, estimation_samples, validation_samples,
  /// level_outputs, level_ripples}.
  nlohmann::ordered_json ToJson() const;
};

/// One design and its closed-loop check on the plant.
struct CommissionAttempt {
  double aggressiveness = 0.5;        ///< the design's aggressiveness (auto_tuning.hpp)
  std::string design;                 ///< BuiltController::Summary()
  nlohmann::ordered_json settings;    ///< BuiltController::SettingsToJson()
  ClosedLoopResult result;            ///< the verification run on the plant
  bool passed = false;                ///< every item of the specification met
  std::vector<std::string> failures;  ///< the specification items not met
  /// The worst overshoot as the specification judges it, percent of the
  /// step: the peak beyond half the step's steady ripple where that ripple is
  /// within its limit (a level the modulation holds inside a valve's gap),
  /// else the peak (docs/commission.md). At most the run's worst overshoot.
  double overshoot_judged_percent = std::numeric_limits<double>::quiet_NaN();
};

/// What Commission did and found (after Ceres' Solver::Summary).
struct CommissionResult {
  /// kSuccess: a controller passed the verification; kPartial: a controller
  /// was designed but failed it (see limits); kStopped: stopped on request;
  /// kFailure: no controller (the reason in message).
  Termination termination = Termination::kFailure;
  std::string message;                   ///< one line: what was met, or why not
  CommissionExperiment experiment;       ///< the experiment's data and measurements
  IdentificationSummary identification;  ///< the models, ranked on the held-out part
  std::string model_file;                ///< DIR/models.json
  std::string chosen_model;              ///< method name of the model the controller uses
  std::string chosen_reason;     ///< why that model (its fits, the better-ranked ones skipped)
  std::string controller_model;  ///< DIR/models.json\#METHOD
  ControllerSettings settings;   ///< the final design's settings (rule auto resolved)
  /// Every verification, the final design last: the one that passed, or when
  /// none did, the one with the fewest failures (then the smallest overshoot).
  std::vector<CommissionAttempt> attempts;
  std::vector<std::string> limits;       ///< what limits the final loop
  std::vector<std::string> suggestions;  ///< what to try when it fails
  double plant_time = 0.0;               ///< s of plant time in all stages
  /// True when the final verification met the specification.
  bool passed() const { return !attempts.empty() && attempts.back().passed; }
  /// {termination, message, experiment, models, chosen_model, controller,
  /// verification (the keys of control --json), passed, limits, suggestions,
  /// plant_time}.
  nlohmann::ordered_json ToJson() const;
};

/// Runs the stages above on `plant`.
/// @throws InvalidArgument for invalid options (naming the field and value).
/// Problems of the plant (no response, a range it cannot reach, a budget too
/// short for its time scale, no settling) end with kFailure and the message.
CommissionResult Commission(Plant& plant, const CommissionOptions& options);

/// Sets the specification of `options` to the default of the plant whose
/// actuator is `actuator` (`pneumid commission` and the app call it before
/// `--spec` or the request's values): overshoot 5 % and settling 0.5 s (the force loop's targets),
/// and for an integrating plant (a positioning drive: the IPA in position mode, on the simulator or
/// behind a plant server that describes it) 2 % and 1 s (docs/position.md).
void SetDefaultSpecification(CommissionOptions& options, const Actuator& actuator);

/// Sets the input gaps of `options` from text, as `--input-gaps` and the
/// app's `input_gaps` give them: "plant" keeps the actuator's own (options.actuator,
/// else PlantActuator(plant)), "none" turns the modulation off, "LO:HI[,LO:HI]"
/// replaces the actuator's gaps (ParseInputGaps).
/// @throws InvalidArgument naming the item that is not LO:HI (ParseInputGaps).
void SetInputGaps(CommissionOptions& options, const Plant& plant, const std::string& text);

/// The loop period commission takes on a PWM actuator when none is given:
/// the PWM period 1/pwm_frequency, or the smallest multiple of it that is at
/// least 3 ms (a faster PWM would give MPC horizons of hundreds of samples for
/// no gain). One duty per PWM period lets the modulation across the valves'
/// gaps alternate at the valves' own rate: on the IPA (300 Hz) the ripple it
/// leaves above 20 N falls from about 1.1 % to 0.4-0.6 % of the set-point
/// against a 10 ms loop (docs/commission.md).
/// @throws InvalidArgument unless pwm_frequency is finite and positive.
double PwmLoopPeriod(double pwm_frequency);

/// The loop period commission runs a simulated `plant` at when none is given:
/// PwmLoopPeriod of its PWM frequency on the IPA simulator, else `fallback`
/// (0.01 s in `pneumid commission` and in the app). The command and the app
/// both take it from here.
double DefaultLoopPeriod(const Plant& plant, double fallback);

/// A simulated plant for commission and the loop period it runs at.
struct CommissionPlant {
  std::unique_ptr<Plant> plant;  ///< built by MakePlant at `Ts`
  double Ts = 0.0;               ///< the given period, else DefaultLoopPeriod
};

/// MakePlant(spec, Ts, options) at the given period, or, when `Ts` is empty,
/// at DefaultLoopPeriod(plant, fallback) (the command and the app build their
/// simulated plant here).
/// @throws InvalidArgument as MakePlant, or when a given Ts or the fallback
/// is not finite and positive.
CommissionPlant MakeCommissionPlant(const std::string& spec, std::optional<double> Ts,
                                    const PlantOptions& options, double fallback = 0.01);

}  // namespace pneumid
