// The identification report of `pneumid report DATA [--methods ...] -o DIR`:
// identifies models of one input/output pair of a dataset by several methods
// and writes DIR/report.html, a self-contained page (html.hpp) with
//   * the dataset (source, samples, sample time, channels) and a step summary,
//   * a parameter table (one row per model: structure, parameters, transfer
//     function) and a metric table (NRMSE fit [%], IAE, RMSE, max error),
//   * figures: measured data with every model simulated on its input
//     (Figure 5 of [1]), step responses of the models (Figure 4), Bode
//     diagram, and residual correlations of the best model with a 99 % band,
//   * the command lines that reproduce the report,
// Axis labels come from the dataset's channel names and units.
// and DIR/models.json with the models in the form of `pneumid identify --json`.
//
// Methods (names of `pneumid identify --method`, identify/identify.hpp):
//   reaction-curve   FOPDT by the process reaction curve [1, Eq. 2]
//   tangent          FOPDT from the inflection tangent (Ziegler-Nichols)
//   ptn              PTn by the tangent-line method [1, Eq. 3], order request.order
//   arx iv4 armax oe bj n4sid ...   polynomial/subspace methods (parametric.hpp)
// A method that fails on the data (e.g. no step for reaction-curve) is listed
// with its error message in the report and in the summary; it does not stop
// the others.
//
// [1] A. A. M. Emhemed, R. Mamat, A. A. M. Faudzi, Jurnal Teknologi 77:20
//     (2015) 115-119.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pneumid/common/termination.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/identify.hpp"

namespace pneumid {

/// Methods, channels and figure settings of WriteIdentificationReport.
struct ReportOptions {
  /// Methods in table order (default: the paper's three).
  std::vector<std::string> methods = {"reaction-curve", "ptn", "arx"};
  IdentifyRequest request;            ///< channels and orders (default ARX(3,3,1), PTn n = 2)
  /// The nonlinear structures (hammerstein, wiener, hw, narx) chosen on the
  /// internal split as `pneumid identify` chooses them when no order is given
  /// (NonlinearOptions::choose_structure); false: the request's orders.
  bool choose_structure = false;
  std::string title;                  ///< default "Identification report: <data source>"
  int residual_max_lag = 25;          ///< largest lag of the residual figure, 1..10000
  double residual_confidence = 0.99;  ///< level of the residual band, in (0, 1)
  /// Bands of +-confidence standard deviations on the step and Bode figures
  /// around models with a parameter covariance (model_uncertainty.hpp); 0 = none.
  double confidence = 0.0;
  /// Command lines shown in the "Reproduce" section (empty = none given).
  std::vector<std::string> commands;
  /// Called as the methods run (identify.hpp, IdentifyProgress); none by default.
  IdentifyProgress progress;
  /// How the data were preprocessed before the report (listed in the data
  /// table and stored with each model in models.json); none by default.
  std::optional<PreprocessRecord> preprocessing;
  /// True for known, non-empty methods, a valid request, residual settings in range and
  /// confidence >= 0; otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

// Termination here: kSuccess, kPartial or kFailure ("success", "partial", "failure";
// common/termination.hpp).

/// What WriteIdentificationReport produced.
struct ReportSummary {
  /// kSuccess: every method gave a model; kPartial: some failed;
  /// kFailure: none did (the report is still written, listing the errors).
  Termination termination = Termination::kSuccess;
  std::string message;                  ///< e.g. "2 of 3 methods failed"
  std::vector<IdentifiedModel> models;  ///< the models identified, ranked best first
  std::vector<std::pair<std::string, std::string>> failures;  ///< method, error
  std::string html_path;                                      ///< DIR/report.html
  std::string models_path;                                    ///< DIR/models.json
  int num_figures = 0;                                        ///< figures in the page
  int num_tables = 0;                                         ///< tables in the page
  /// One line: termination, models, failures, figures, tables and the page's path.
  std::string BriefReport() const;
};

/// Runs the methods and writes DIR/report.html and DIR/models.json (DIR is
/// created when missing).
/// @throws InvalidArgument for invalid options or channels; DataError when DIR
///         cannot be created or written.
ReportSummary WriteIdentificationReport(const Dataset& data, const ReportOptions& options,
                                        const std::string& dir);

}  // namespace pneumid
