#include "pneumid/identify/evaluation/validation.hpp"

#include <cmath>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {

bool CompareOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (horizon < 0)
    return fail(fmt::format("horizon must be >= 0 (0 = simulation), got {}", horizon));
  if (skip < 0) return fail(fmt::format("skip must be >= 0, got {}", skip));
  if (input < 0) return fail(fmt::format("input must be >= 0, got {}", input));
  if (output < 0) return fail(fmt::format("output must be >= 0, got {}", output));
  return true;
}

namespace {

CompareResult Finish(const Dataset& data, Eigen::VectorXd y, Eigen::VectorXd yhat,
                     const CompareOptions& o) {
  PNEUMID_CHECK(o.skip + 2 <= y.size(), "skip = {} leaves fewer than 2 of {} samples", o.skip,
                y.size());
  CompareResult r;
  r.t = data.time();
  r.horizon = o.horizon;
  const Eigen::Index n = y.size() - o.skip;
  if (yhat.allFinite()) {
    r.fit_percent = NrmseFit(y.tail(n), yhat.tail(n));
    r.rmse = Rmse(y.tail(n), yhat.tail(n));
  } else {
    r.fit_percent = -std::numeric_limits<double>::infinity();
    r.rmse = std::numeric_limits<double>::infinity();
  }
  r.y = std::move(y);
  r.yhat = std::move(yhat);
  return r;
}

void CheckOptions(const CompareOptions& o, const Dataset& data) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid compare options: {}", error);
  PNEUMID_CHECK(o.output < data.num_outputs(), "output column {} out of range [0, {})", o.output,
                data.num_outputs());
}

}  // namespace

CompareResult Compare(const PolynomialModel& model, const Dataset& data,
                      const CompareOptions& options) {
  CheckOptions(options, data);
  model.Validate();
  Eigen::MatrixXd u;
  if (model.num_inputs() == 1) {
    PNEUMID_CHECK(options.input < data.num_inputs(), "input column {} out of range [0, {})",
                  options.input, data.num_inputs());
    u = data.u(options.input);
  } else {
    u = data.inputs();
  }
  const Eigen::VectorXd y = data.y(options.output);
  return Finish(data, y, Predict(model, y, u, options.horizon), options);
}

CompareResult Compare(const TransferFunction& model, const Dataset& data,
                      const CompareOptions& options) {
  CheckOptions(options, data);
  PNEUMID_CHECK(options.horizon == 0,
                "a transfer function has no noise model: only simulation (horizon 0) is "
                "defined, got horizon {}",
                options.horizon);
  PNEUMID_CHECK(options.input < data.num_inputs(), "input column {} out of range [0, {})",
                options.input, data.num_inputs());
  data.RequireUniform();
  const double Ts = data.SampleTime();
  if (model.IsDiscrete())
    PNEUMID_CHECK(std::abs(model.Ts() - Ts) <= 1e-6 * Ts,
                  "the model's sample time {} s differs from the data's {} s", model.Ts(), Ts);
  // The one simulation of a model on data (model_evaluation.hpp), at rest at 0.
  IdentifiedModel at_rest;
  at_rest.tf = model;
  return Finish(data, data.y(options.output), SimulateModel(at_rest, data, options.input),
                options);
}

Dataset SliceDataset(const Dataset& data, Eigen::Index begin, Eigen::Index end) {
  PNEUMID_CHECK(begin >= 0 && end <= data.size() && begin < end,
                "sample range [{}, {}) is empty or outside [0, {})", begin, end, data.size());
  const Eigen::Index n = end - begin;
  Dataset d(data.time().segment(begin, n), data.inputs().middleRows(begin, n),
            data.outputs().middleRows(begin, n), data.input_channels(), data.output_channels());
  d.set_time_channel(data.time_channel());
  d.set_source(data.source());
  return d;
}

std::pair<Dataset, Dataset> SplitDataset(const Dataset& data, double fraction) {
  PNEUMID_CHECK(fraction > 0.0 && fraction < 1.0, "split fraction must be in (0, 1), got {}",
                fraction);
  const Eigen::Index n = data.size();
  const Eigen::Index k = static_cast<Eigen::Index>(std::llround(fraction * static_cast<double>(n)));
  PNEUMID_CHECK(k >= 2 && n - k >= 2,
                "splitting {} samples at {} leaves a part with fewer than 2 samples", n, fraction);
  return {SliceDataset(data, 0, k), SliceDataset(data, k, n)};
}

}  // namespace pneumid
