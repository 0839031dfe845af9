// pneumid orders DATA: ARX order and delay selection table (arxstruc/selstruc).
#include <iostream>
#include <memory>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "validators.hpp"
#include "data_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/parametric/order_selection.hpp"
#include "pneumid/identify/evaluation/validation.hpp"

namespace pneumid::cli {
namespace {

struct OrdersArgs {
  DataOptions data;
  PreprocessArgs preprocess;
  std::string na = "1:5", nb = "1:5", nk = "0:3";
  double split = 0.0;
  int top = 0;
  bool json = false;
  std::string operating_point = "auto";
};

void Run(const OrdersArgs& a) {
  OrderSelectionOptions o;
  o.na = OrderRange::Parse(a.na);
  o.nb = OrderRange::Parse(a.nb);
  o.nk = OrderRange::Parse(a.nk);
  o.operating_point = OperatingPointKindFromString(a.operating_point);
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "{}", error);
  PNEUMID_CHECK(a.split == 0.0 || (a.split > 0.0 && a.split < 1.0),
                "--split must be in (0, 1), got {}", a.split);
  PNEUMID_CHECK(a.top >= 0, "--top must be >= 0, got {}", a.top);
  Dataset loaded = LoadFromOptions(a.data);
  RequireSingleInputOutput(loaded, a.data, "orders");
  const Dataset data = Preprocess(std::move(loaded), ToPreprocessOptions(a.preprocess));
  OrderSelection s;
  if (a.split > 0.0) {
    const auto [est, val] = SplitDataset(data, a.split);
    s = SelectArxOrders(est, o, &val);
  } else {
    s = SelectArxOrders(data, o);
  }
  if (a.json) {
    std::cout << s.ToJson().dump(2) << "\n";
    return;
  }
  const std::vector<OrderCriterion> crit = {OrderCriterion::kLoss, OrderCriterion::kAic,
                                            OrderCriterion::kAicc, OrderCriterion::kFpe,
                                            OrderCriterion::kMdl};
  std::cout << fmt::format("ARX order selection: {} candidates, N = {} rows, loss on {} data\n",
                           s.candidates.size(), s.num_rows,
                           s.validation ? "validation" : "estimation");
  if (s.u0 != 0.0 || s.y0 != 0.0)
    std::cout << fmt::format("operating point u0 = {:.6g}, y0 = {:.6g}: the models are ARX from "
                             "u - u0 to y - y0 (--operating-point zero: the raw signals)\n",
                             s.u0, s.y0);
  std::vector<std::size_t> order(s.candidates.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  if (a.top > 0) {
    std::stable_sort(order.begin(), order.end(),
                     [&](auto x, auto y) { return s.candidates[x].mdl < s.candidates[y].mdl; });
    order.resize(std::min<std::size_t>(order.size(), a.top));
  }
  std::cout << fmt::format("{:>3} {:>3} {:>3} {:>3} {:>13} {:>13} {:>13} {:>13} {:>13}\n", "na",
                           "nb", "nk", "d", "loss", "AIC", "AICc", "FPE", "MDL");
  for (std::size_t i : order) {
    const auto& c = s.candidates[i];
    std::string line = fmt::format("{:>3} {:>3} {:>3} {:>3}", c.na, c.nb, c.nk, c.num_parameters);
    for (auto k : crit) line += fmt::format(" {:>12.6g}{}", c.Value(k), s.Best(k) == i ? "*" : " ");
    std::cout << line << "\n";
  }
  std::cout << "best (* in the table):\n";
  for (auto k : crit) {
    const auto& b = s.candidates[s.Best(k)];
    std::cout << fmt::format("  {:<5} na = {}, nb = {}, nk = {}\n", ToString(k), b.na, b.nb, b.nk);
  }
}

static Registrar reg(
    "orders", "ARX order and delay selection: loss, AIC, AICc, FPE, MDL over na, nb, nk",
    [](CLI::App& app) {
      auto args = std::make_shared<OrdersArgs>();
      AddDataOptions(app, args->data);
      AddPreprocessOptions(app, args->preprocess);
      app.add_option("--na-range", args->na, "A orders MIN:MAX (or N)")->capture_default_str();
      app.add_option("--nb-range", args->nb, "B orders MIN:MAX (or N)")->capture_default_str();
      app.add_option("--nk-range", args->nk, "input delays MIN:MAX in samples (or N)")
          ->capture_default_str();
      app.add_option("--split", args->split,
                     "Estimate on the first fraction of the data and measure the loss on the "
                     "rest, e.g. 0.7 (default: all data, loss on the estimation data)");
      app.add_option("--top", args->top, "Print only the N best candidates by MDL (0 = all)")
          ->check(AtLeast(0));
      app.add_option("--operating-point", args->operating_point,
                     "The levels (u0, y0) the ARX models are fitted about: auto (default: zero "
                     "for a record that starts at rest at zero, else the means of the "
                     "estimation data), zero (the raw signals), mean, initial (the first "
                     "samples' level)")
          ->capture_default_str()
          ->check(NameOf([](const std::string& s) { OperatingPointKindFromString(s); }));
      app.add_flag("--json", args->json, "Print the table and the best orders as JSON");
      app.callback([args] { Run(*args); });
    });

}  // namespace
}  // namespace pneumid::cli
