#include "pneumid/workflow/identify_workflow.hpp"

#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/parametric/process_model.hpp"

namespace pneumid {

PreprocessOptions PreprocessSettings::ToOptions() const {
  PreprocessOptions o;
  auto flag = [](const char* name, auto&& parse) {
    try {
      return parse();
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(fmt::format("{}: {}", name, e.what()));
    }
  };
  if (!window.empty()) o.window = flag("--window", [&] { return TimeWindow::Parse(window); });
  o.resample_ts = resample;
  o.remove_initial = remove_initial;
  o.detrend = flag("--detrend", [&] { return DetrendKindFromString(detrend); });
  PNEUMID_CHECK(!(o.remove_initial && o.detrend != DetrendKind::kNone),
                "--remove-initial and --detrend {} both remove offsets: give one of them", detrend);
  if (!filter.empty()) o.filter = flag("--filter", [&] { return FilterSpec::Parse(filter); });
  PNEUMID_CHECK(decimate >= 1, "--decimate must be an integer factor >= 1, got {}", decimate);
  o.decimate = decimate;
  std::string why;
  PNEUMID_CHECK(o.IsValid(&why), "{}", why);
  return o;
}

bool IdentifyWorkflowOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string message) {
    if (error != nullptr) *error = std::move(message);
    return false;
  };
  std::string why;
  if (!request.IsValid(&why)) return fail(why);
  if (!(split == 0.0 || (split > 0.0 && split < 1.0)))
    return fail(fmt::format("--split must be a fraction in (0, 1), e.g. 0.7, got {}", split));
  return true;
}

nlohmann::json IdentifyWorkflowResult::ToJson() const {
  const std::vector<IdentifiedModel>& models = summary.models;
  if (models.empty()) return nullptr;
  const bool held_out = summary.validation_samples > 0;
  nlohmann::json j = ModelFileDocument(models);
  bool determined = false;
  for (std::size_t i = 0; i < models.size(); ++i) {
    j["models"][i]["rank_reason"] = RankReason(models[i]);
    if (std::isfinite(models[i].determined_fit_percent)) {
      j["models"][i]["determined_fit_percent"] = models[i].determined_fit_percent;
      determined = true;
    }
  }
  j["best"] = models.front().method;
  j["ranked_by"] = determined ? "determined_fit_percent"
                   : held_out ? "validation_fit_percent"
                              : "fit_percent";
  j["estimation_samples"] = summary.estimation_samples;
  j["validation_samples"] = summary.validation_samples;
  j["failures"] = nlohmann::json::array();
  for (const auto& [method, reason] : summary.failures)
    j["failures"].push_back({{"method", method}, {"reason", reason}});
  j["termination"] = ToString(summary.termination);
  j["message"] = summary.message;
  j["warnings"] = summary.warnings;
  return j;
}

IdentifyWorkflowResult RunIdentifyWorkflow(const IdentifyWorkflowOptions& o, const Dataset& raw,
                                           const Dataset* validation_raw,
                                           const IdentifyProgress& progress) {
  std::string why;
  PNEUMID_CHECK(o.request.IsValid(&why), "{}", why);
  PNEUMID_CHECK(validation_raw == nullptr || o.split == 0.0,
                "--validation and --split exclude each other: give held-out data as a file or "
                "as a fraction of DATA");
  PNEUMID_CHECK(o.IsValid(&why), "{}", why);
  const bool automatic = o.methods == "auto";
  std::vector<std::string> methods;  // auto: chosen once the data are preprocessed
  if (!automatic) methods = ParseMethodList(o.methods);
  const PreprocessOptions prep = o.preprocess.ToOptions();
  IdentifyWorkflowResult out;
  out.data = Preprocess(raw, prep, &out.record);
  std::string auto_warning;  // auto on a record that is not a step test
  if (automatic) methods = AutoMethods(out.data, o.request, {"reaction-curve"}, &auto_warning);
  std::optional<Dataset> validation;
  // The validation data get the estimation data's preprocessing, with the
  // offsets measured on the estimation data (not re-estimated).
  if (validation_raw) validation.emplace(ApplyRecorded(*validation_raw, out.record));
  IdentifyOptions options;
  options.step.fit.loss = RobustLossFromString(o.loss);
  options.split = o.split;
  options.nonlinear = o.nonlinear;
  out.summary = IdentifyModels(methods, out.data, o.request, options,
                               validation ? &*validation : nullptr, progress);
  if (!auto_warning.empty())
    out.summary.warnings.insert(out.summary.warnings.begin(), auto_warning);
  if (!out.record.IsIdentity())
    for (IdentifiedModel& m : out.summary.models) m.preprocessing = out.record;
  return out;
}

}  // namespace pneumid
