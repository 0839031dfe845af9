// The paper reproduced end to end (`pneumid paper`): every number of
// docs/paper.md next to the value pneumid obtains, and
// Figures 4-6 of [1], from the built-in IPA simulator.
//
// Workflow (RunPaper):
//   1. step test on the IPA simulator (force mode, plant/ipa_simulator.hpp):
//      duty 0.61 % held, stepped to 82 % at `step_time`, force recorded at Ts;
//   2. FOPDT by the reaction curve [1, Eq. 2], PTn (n = 2) by the tangent-line
//      method [1, Eq. 3], ARX(3,3,1) [1, Eq. 4-5] and its zoh d2c form [1, Eq. 6];
//   2b. a PRBS experiment on the twin and ARX(3,3,1) from it, next to Eq. 5
//      (static gain, poles, whether a zoh continuous equivalent exists);
//   3. the paper's own ARX model (Eq. 5): static gain, discrete poles, d2c
//      (Eq. 6), continuous poles, 63.2 % time and Ziegler-Nichols tangent of
//      its unit step;
//   4. Figure 4 (step responses of the FOPDT and PTn models) and Figure 5
//      (data, FOPDT, PTn, ARX on one time axis);
//   5. tuning from the FOPDT as the paper reads it off the step test (K = dy/du,
//      tau = t63, theta = 0.001 s): conventional (Shridhar-Cooper: P, M = 5,
//      lambda) and modified (P, M = 10, lambda = 1.92) [1, sec. 5], control/tuning.hpp;
//   6. the reference closed loops of docs/paper.md, reference value 6 (DMC with the
//      paper's P, M, lambda on the paper's FOPDT, unit set-point step): first
//      move, rise time, overshoot, settling time;
//   7. Figure 6: DMC with both tunings (model: the FOPDT of step 5) driving
//      the IPA simulator through set-point steps and a load disturbance,
//      with the actuator limited to 0..100 % duty.
// Each row says where pneumid's value differs from the paper's and why (the
// simulator is not the authors' rig; typographical errors of the paper).
//
// [1] A. A. M. Emhemed, R. Mamat, A. A. M. Faudzi, Non-parametric
//     identification techniques for intelligent pneumatic actuator, Jurnal
//     Teknologi 77:20 (2015) 115-119.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pneumid/common/termination.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/report/plot.hpp"

namespace pneumid {

/// Settings of RunPaper: the step test, the PRBS experiment and the Figure 6 loop.
struct PaperOptions {
  double Ts = 0.01;            ///< s, sample time of the paper
  double step_time = 0.5;      ///< s, when the duty steps from u_initial to u_final
  double duration = 3.0;       ///< s, length of the step test
  double u_initial = 0.61;     ///< %, duty before the step (paper)
  double u_final = 82.0;       ///< %, duty after the step (paper)
  std::uint64_t seed = 1;      ///< sensor-noise seed of the simulator
  std::string ipa_config;      ///< TOML file with IPA parameters (empty = defaults)
  /// The twin's PRBS experiment (section 2: ARX(3,3,1) from rich data next to
  /// Eq. 5), signal spec of plant/signal.hpp and its length in s; an empty
  /// spec skips it. The ARX is estimated after `prbs_skip` s, with the means
  /// removed (the model has no offset term).
  std::string prbs = "prbs:low=0.61,high=82,order=8,clock=0.05";
  double prbs_duration = 60.0;  ///< s, length of the PRBS experiment (100 Ts .. 3600 s)
  double prbs_skip = 2.0;       ///< s, initial transient left out of the ARX estimation
  double loop_duration = 6.0;   ///< s, Figure 6 run
  /// Figure 6 set-point levels (N), each held `loop_dwell` s.
  std::vector<double> loop_levels = {0.0, 100.0, 60.0, 60.0};
  double loop_dwell = 1.5;   ///< s
  double load_time = 5.0;    ///< s, load disturbance step (NaN = none)
  double load_size = -15.0;  ///< N
  /// True when the times, duties (distinct, 0..100 %), levels and PRBS settings are in
  /// range; otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// One line of the side-by-side table.
struct PaperRow {
  std::string section;   ///< reference value of docs/paper.md, e.g. "2 ARX model"
  std::string quantity;  ///< e.g. "a1"
  std::string paper;     ///< the paper's value as printed
  std::string pneumid;   ///< pneumid's value
  std::string note;      ///< empty when they agree; otherwise why they differ
};

// Termination here: kSuccess or kPartial ("success", "partial"; common/termination.hpp).

/// Everything RunPaper obtained: the comparison rows, data, models and figures.
struct PaperResult {
  /// kPartial when a step failed numerically (listed in `problems`); the
  /// rows that could be computed are still filled.
  Termination termination = Termination::kSuccess;
  std::vector<std::string> problems;      ///< steps that failed, with their error
  std::vector<PaperRow> rows;             ///< the side-by-side table, in workflow order
  Dataset step_test;                      ///< the simulated step test (duty %, force N)
  Dataset prbs_test;                      ///< the twin's PRBS experiment (empty when skipped)
  std::vector<IdentifiedModel> models;    ///< reaction-curve, ptn, arx (those that succeeded)
  std::vector<Figure> figures;            ///< Figure 4, 5, 6 (those that could be drawn)
  std::vector<std::string> figure_names;  ///< "fig4", "fig5", "fig6"
  /// One line: termination, number of quantities (with a note), figures and problems.
  std::string BriefReport() const;
  /// {"rows": [{"quantity", "paper", "pneumid", "note", "section"}], ...}
  nlohmann::json ToJson() const;
  /// Fixed-width side-by-side table for a terminal.
  std::string TableText() const;
};

/// Runs the workflow above.
/// @throws InvalidArgument for invalid options; DataError for an unreadable
///         ipa_config file.
PaperResult RunPaper(const PaperOptions& options = {});

/// Writes fig4/fig5/fig6 as .png and .svg into dir (created when missing);
/// returns the paths written. @throws DataError when dir cannot be written.
std::vector<std::string> WritePaperFigures(const PaperResult& result, const std::string& dir);

}  // namespace pneumid
