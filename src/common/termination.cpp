#include "pneumid/common/termination.hpp"

#include "pneumid/common/enum_names.hpp"

namespace pneumid {
namespace {

constexpr EnumName<Termination> kTerminationNames[] = {
    {Termination::kConvergence, "convergence"},
    {Termination::kNoConvergence, "no_convergence"},
    {Termination::kRankDeficient, "rank_deficient"},
    {Termination::kSuccess, "success"},
    {Termination::kPartial, "partial"},
    {Termination::kStopped, "stopped"},
    {Termination::kFailure, "failure"},
    // Spellings of earlier versions, accepted when reading.
    {Termination::kSuccess, "completed"},
    {Termination::kFailure, "fault"},
};

}  // namespace

std::string ToString(Termination t) { return std::string(EnumToString(kTerminationNames, t)); }

Termination TerminationFromString(const std::string& name) {
  return EnumFromString(kTerminationNames, name, "termination", /*ignore_case=*/true);
}

}  // namespace pneumid
