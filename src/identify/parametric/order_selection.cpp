#include "pneumid/identify/parametric/order_selection.hpp"

#include <charconv>
#include <cmath>
#include <limits>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/identify/parametric/parametric.hpp"

namespace pneumid {

namespace {
int ParseInt(const std::string& s, const std::string& whole) {
  int v = 0;
  const auto* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  PNEUMID_CHECK(r.ec == std::errc() && r.ptr == end && !s.empty(),
                "order range '{}': '{}' is not an integer (expected N or MIN:MAX)", whole, s);
  return v;
}
}  // namespace

OrderRange OrderRange::Parse(const std::string& text) {
  OrderRange r;
  const auto colon = text.find(':');
  if (colon == std::string::npos) {
    r.min = r.max = ParseInt(text, text);
  } else {
    r.min = ParseInt(text.substr(0, colon), text);
    r.max = ParseInt(text.substr(colon + 1), text);
  }
  PNEUMID_CHECK(r.min <= r.max, "order range '{}': min {} > max {}", text, r.min, r.max);
  return r;
}

std::string OrderRange::ToString() const { return fmt::format("{}:{}", min, max); }

namespace {
constexpr EnumName<OrderCriterion> kOrderCriterionNames[] = {
    {OrderCriterion::kLoss, "loss"}, {OrderCriterion::kAic, "aic"}, {OrderCriterion::kAicc, "aicc"},
    {OrderCriterion::kFpe, "fpe"},   {OrderCriterion::kMdl, "mdl"},
};
}  // namespace

std::string ToString(OrderCriterion v) {
  return std::string(EnumToString(kOrderCriterionNames, v));
}

OrderCriterion OrderCriterionFromString(const std::string& name) {
  return EnumFromString(kOrderCriterionNames, name, "criterion");
}

bool OrderSelectionOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (na.min < 0 || na.min > na.max)
    return fail(fmt::format("na range {} invalid (need 0 <= min <= max)", na.ToString()));
  if (nb.min < 1 || nb.min > nb.max)
    return fail(fmt::format("nb range {} invalid (need 1 <= min <= max)", nb.ToString()));
  if (nk.min < 0 || nk.min > nk.max)
    return fail(fmt::format("nk range {} invalid (need 0 <= min <= max)", nk.ToString()));
  if (input < 0 || output < 0) return fail("input and output columns must be >= 0");
  return true;
}

double OrderCandidate::Value(OrderCriterion c) const {
  switch (c) {
    case OrderCriterion::kLoss:
      return loss;
    case OrderCriterion::kAic:
      return aic;
    case OrderCriterion::kAicc:
      return aicc;
    case OrderCriterion::kFpe:
      return fpe;
    case OrderCriterion::kMdl:
      return mdl;
  }
  return loss;
}

std::size_t OrderSelection::Best(OrderCriterion c) const {
  PNEUMID_CHECK(!candidates.empty(), "no candidates");
  std::size_t best = 0;
  for (std::size_t i = 1; i < candidates.size(); ++i)
    if (candidates[i].Value(c) < candidates[best].Value(c)) best = i;
  return best;
}

nlohmann::json OrderSelection::ToJson() const {
  nlohmann::json j;
  j["num_rows"] = num_rows;
  j["loss_on"] = validation ? "validation" : "estimation";
  j["operating_point"] = {{"u0", u0}, {"y0", y0}};
  nlohmann::json cs = nlohmann::json::array();
  for (const auto& c : candidates)
    cs.push_back({{"na", c.na},
                  {"nb", c.nb},
                  {"nk", c.nk},
                  {"num_parameters", c.num_parameters},
                  {"loss", c.loss},
                  {"aic", c.aic},
                  {"aicc", c.aicc},
                  {"fpe", c.fpe},
                  {"mdl", c.mdl}});
  j["candidates"] = cs;
  nlohmann::json best;
  for (auto c : {OrderCriterion::kLoss, OrderCriterion::kAic, OrderCriterion::kAicc,
                 OrderCriterion::kFpe, OrderCriterion::kMdl}) {
    const auto& b = candidates[Best(c)];
    best[ToString(c)] = {{"na", b.na}, {"nb", b.nb}, {"nk", b.nk}};
  }
  j["best"] = best;
  return j;
}

OrderSelection SelectArxOrders(const Dataset& data, const OrderSelectionOptions& o,
                               const Dataset* validation) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid order-selection options: {}", error);
  PNEUMID_CHECK(o.input < data.num_inputs(), "input column {} out of range [0, {})", o.input,
                data.num_inputs());
  PNEUMID_CHECK(o.output < data.num_outputs(), "output column {} out of range [0, {})", o.output,
                data.num_outputs());
  data.RequireUniform();
  // About the operating point (OrderSelectionOptions::operating_point).
  const Eigen::VectorXd y_raw = data.y(o.output), u_raw = data.u(o.input);
  double u0 = 0.0, y0 = 0.0;
  const Eigen::Index n_init =
      std::max<Eigen::Index>(1, std::min<Eigen::Index>(20, u_raw.size() / 50));
  switch (o.operating_point) {
    case OperatingPointKind::kAuto:
      if (!StartsAtRestAtZero(u_raw, y_raw)) {
        u0 = u_raw.mean();
        y0 = y_raw.mean();
      }
      break;
    case OperatingPointKind::kZero:
      break;
    case OperatingPointKind::kMean:
      u0 = u_raw.mean();
      y0 = y_raw.mean();
      break;
    case OperatingPointKind::kInitial:
      u0 = u_raw.head(n_init).mean();
      y0 = y_raw.head(n_init).mean();
      break;
  }
  const Eigen::VectorXd y = (y_raw.array() - y0).matrix();
  const Eigen::VectorXd u = (u_raw.array() - u0).matrix();
  const int max_ulag = o.nk.max + o.nb.max - 1;
  const int n0 = std::max(o.na.max, max_ulag);
  const int dmax = o.na.max + o.nb.max;
  data.RequireSamples(n0 + 2 * dmax + 2, "order selection");
  const Eigen::Index rows = y.size() - n0;
  // All lagged signals once: -y(t-1..na_max), u(t-0..max_ulag).
  Eigen::MatrixXd ylags(rows, o.na.max), ulags(rows, max_ulag + 1);
  for (int l = 1; l <= o.na.max; ++l) ylags.col(l - 1) = -y.segment(n0 - l, rows);
  for (int l = 0; l <= max_ulag; ++l) ulags.col(l) = u.segment(n0 - l, rows);
  const Eigen::VectorXd target = y.tail(rows);
  OrderSelection sel;
  sel.num_rows = rows;
  sel.validation = validation != nullptr;
  sel.u0 = u0;
  sel.y0 = y0;
  const double N = static_cast<double>(rows);
  for (int na = o.na.min; na <= o.na.max; ++na) {
    for (int nb = o.nb.min; nb <= o.nb.max; ++nb) {
      for (int nk = o.nk.min; nk <= o.nk.max; ++nk) {
        ArxOptions ao;
        ao.na = na;
        ao.nb = {nb};
        ao.nk = {nk};
        ArxAccumulator acc(ao);
        Eigen::MatrixXd m(rows, na + nb + 1);
        m << ylags.leftCols(na), ulags.middleCols(nk, nb), target;
        acc.AddRows(m);
        const ArxResult r = acc.Solve(data.SampleTime());
        OrderCandidate c;
        c.na = na;
        c.nb = nb;
        c.nk = nk;
        c.num_parameters = na + nb;
        if (validation != nullptr) {
          Eigen::MatrixXd uv = (validation->u(o.input).array() - u0).matrix();
          const Eigen::VectorXd eps = PredictionErrors(
              r.model, (validation->y(o.output).array() - y0).matrix(), uv);
          const Eigen::Index skip = std::min<Eigen::Index>(n0, eps.size() - 1);
          c.loss =
              eps.tail(eps.size() - skip).squaredNorm() / static_cast<double>(eps.size() - skip);
        } else {
          c.loss = r.summary.loss;
        }
        const double d = c.num_parameters;
        const double V = std::max(c.loss, std::numeric_limits<double>::min());
        c.aic = N * std::log(V) + 2 * d;
        c.aicc = N - d - 1 > 0 ? c.aic + 2 * d * (d + 1) / (N - d - 1)
                               : std::numeric_limits<double>::infinity();
        c.fpe = d < N ? V * (1 + d / N) / (1 - d / N) : std::numeric_limits<double>::infinity();
        c.mdl = N * std::log(V) + d * std::log(N);
        sel.candidates.push_back(c);
      }
    }
  }
  return sel;
}

int EstimateDelay(const Dataset& data, int na, int nb, int nk_min, int nk_max, int input,
                  int output) {
  OrderSelectionOptions o;
  o.na = {na, na};
  o.nb = {nb, nb};
  o.nk = {nk_min, nk_max};
  o.input = input;
  o.output = output;
  o.operating_point = OperatingPointKind::kZero;  // the raw signals, as delayest
  const OrderSelection s = SelectArxOrders(data, o);
  return s.candidates[s.Best(OrderCriterion::kLoss)].nk;
}

}  // namespace pneumid
