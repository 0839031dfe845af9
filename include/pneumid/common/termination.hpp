// How a computation ended, one vocabulary for estimators, fits, workflows and
// loops (after Ceres' TerminationType in include/ceres/types.h). Every summary
// of the library (EstimationSummary, ProcessFitSummary, ReportSummary,
// PaperResult, LoopSummary) has a `termination` of this type and a message;
// JSON output writes ToString(termination).
#pragma once

#include <string>

namespace pneumid {

/// How a computation ended (the `termination` of every summary); see IsSuccess.
enum class Termination {
  kConvergence,    ///< "convergence": an estimator converged (or solved in closed form)
  kNoConvergence,  ///< "no_convergence": iteration limit reached; the last iterate is returned
  kRankDeficient,  ///< "rank_deficient": regressors not of full rank; minimum-norm solution
  kSuccess,        ///< "success": a workflow or loop ran to the end
  kPartial,        ///< "partial": some steps failed; the others' results are kept
  kStopped,        ///< "stopped": stopped on request (SIGINT/SIGTERM, RequestStop())
  kFailure,        ///< "failure": no usable result (numerical breakdown, safety fault)
};

/// "convergence", "no_convergence", "rank_deficient", "success", "partial",
/// "stopped", "failure".
std::string ToString(Termination t);
/// Inverse of ToString; also accepts the upper-case spellings ("CONVERGENCE")
/// and "completed" (= success) and "fault" (= failure) written by earlier
/// versions. @throws InvalidArgument listing the valid names.
Termination TerminationFromString(const std::string& name);

/// True for kConvergence and kSuccess: the result is complete and usable.
inline bool IsSuccess(Termination t) {
  return t == Termination::kConvergence || t == Termination::kSuccess;
}

}  // namespace pneumid
