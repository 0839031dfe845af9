#include "pneumid/control/controller_factory.hpp"

#include <sstream>
#include <vector>

#include "pneumid/common/check.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/control/gpc.hpp"

namespace pneumid {

BuiltController MakeController(const TransferFunction& model, double Ts,
                               const ControllerSpec& spec) {
  BuiltController b;
  switch (spec.type) {
    case ControllerType::kDmc: {
      b.tuning = Tune(model, Ts, spec.tuning);
      DmcOptions o;
      o.P = b.tuning.P;
      o.M = b.tuning.M;
      o.lambda = b.tuning.lambda;
      o.limits = spec.limits;
      o.constrained = spec.constrained;
      o.y_min = spec.y_min;
      o.y_max = spec.y_max;
      b.controller = std::make_unique<DmcController>(model, Ts, o);
      break;
    }
    case ControllerType::kGpc: {
      PNEUMID_CHECK(!spec.constrained,
                    "the constrained form is implemented for dmc (QDMC); gpc clips its input");
      b.tuning = Tune(model, Ts, spec.tuning);
      GpcOptions o;
      o.N1 = 1;
      o.N2 = b.tuning.P;
      o.Nu = b.tuning.M;
      o.lambda = b.tuning.lambda;
      o.limits = spec.limits;
      if (spec.t_filter == "A" || spec.t_filter == "a") {
        o.t_equals_a = true;
      } else if (spec.t_filter != "1" && !spec.t_filter.empty()) {
        std::string text = spec.t_filter;
        for (char& c : text)
          if (c == ',' || c == ';') c = ' ';
        std::istringstream in(text);
        std::vector<double> coef;
        double v;
        while (in >> v) coef.push_back(v);
        PNEUMID_CHECK(in.eof() && !coef.empty(),
                      "T filter '{}': expected '1', 'A' or coefficients like '1 -0.8'",
                      spec.t_filter);
        o.t_polynomial = Eigen::Map<Eigen::VectorXd>(coef.data(), coef.size());
      }
      b.controller = std::make_unique<GpcController>(model, Ts, o);
      break;
    }
    case ControllerType::kPid: {
      b.fopdt = FopdtFromModel(model);
      b.pid_gains = TunePid(b.fopdt.K, b.fopdt.tau, b.fopdt.theta, Ts, spec.pid_rule, spec.tau_c);
      PidOptions o;
      o.gains = b.pid_gains;
      o.limits = spec.limits;
      b.controller = std::make_unique<PidController>(Ts, o);
      break;
    }
  }
  return b;
}

}  // namespace pneumid
