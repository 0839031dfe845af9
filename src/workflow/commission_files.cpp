#include "pneumid/workflow/commission_files.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include <fmt/format.h>

#include "pneumid/codegen/c_codegen.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/data/csv.hpp"
#include "pneumid/report/figures.hpp"
#include "pneumid/workflow/commission_report.hpp"

namespace pneumid {

namespace {

std::string TomlString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// A model file reference (FILE[#METHOD]) made absolute; an inline spec
// (tf:num=..,den=..) as it is.
std::string ModelReference(const std::string& spec) {
  const std::string file = spec.substr(0, spec.find('#'));
  if (!std::filesystem::exists(file)) return spec;
  return std::filesystem::absolute(file).string() + spec.substr(file.size());
}

// controller.toml: model, controller and its settings, limits, loop, I/O, safety.
void WriteControllerToml(const std::string& path, const CommissionResult& r,
                         const CommissionFilesOptions& o) {
  std::ofstream out(path);
  const ControllerSettings& s = r.settings;
  const auto& ex = r.experiment;
  out << "# Controller configuration written by `pneumid commission` (" << r.message << ").\n"
      << "# Use: pneumid control --config " << path << " --setpoint ... --duration ...\n"
      << "#      pneumid run --config " << path << "\n"
      << "#      pneumid codegen --config " << path << " -o DIR\n\n";
  out << "[controller]\n"
      << "model = " << TomlString(ModelReference(r.controller_model)) << "\n"
      << "type = " << TomlString(s.controller) << "\n";
  if (s.rule == "explicit") {  // a GPC: the horizons and lambda of the DMC's auto design
    out << "rule = \"explicit\"\n"
        << fmt::format("P = {}\nM = {}\nlambda = {}\n", s.P, s.M, s.lambda)
        << "t_filter = " << TomlString(s.t_filter) << "\n";
  } else if (std::isnan(s.pid_kc)) {
    out << "rule = \"auto\"\n"
        << fmt::format("overshoot = {}\n", s.overshoot)
        << fmt::format("aggressiveness = {}\n", s.aggressiveness);
    if (std::isfinite(s.response_time)) out << fmt::format("response_time = {}\n", s.response_time);
  } else {  // a PD designed on an integrating model: its gains
    out << fmt::format("Kc = {}\nTd = {}\n", s.pid_kc, s.pid_td);
  }
  out << fmt::format("u_min = {}\nu_max = {}\n", s.limits.u_min, s.limits.u_max);
  if (!s.input_gaps.empty()) out << "input_gaps = " << TomlString(s.input_gaps) << "\n";
  if (std::isfinite(s.measurement_noise))
    out << fmt::format("measurement_noise = {}\n", s.measurement_noise);
  out << "\n[loop]\n"
      << fmt::format("period = {}\n", o.Ts)
      << fmt::format("duration = {}\n\n", r.attempts.back().result.t.size() * o.Ts);
  if (o.io == "sim")
    out << "[io]\nbackend = \"sim\"\nplant = " << TomlString(o.plant) << "\n\n";
  else
    out << "[io]\nbackend = " << TomlString(o.io) << "\n\n";
  const double span = ex.reachable_max - ex.reachable_min;
  out << "[safety]\n"
      << fmt::format("u_min = {}\nu_max = {}\n", s.limits.u_min, s.limits.u_max)
      << fmt::format("y_min = {}\ny_max = {}\n", ex.reachable_min - 0.5 * span,
                     ex.reachable_max + 0.5 * span);
  if (!out) throw DataError(fmt::format("{}: cannot write", path));
}

void WriteVerificationCsv(const std::string& path, const ClosedLoopResult& cl) {
  std::ofstream out(path);
  out << "t,r,y,u,d\n";
  for (Eigen::Index k = 0; k < cl.t.size(); ++k)
    out << fmt::format("{:.6g},{},{},{},{}\n", cl.t(k), cl.r(k), cl.y(k), cl.u(k), cl.d(k));
  if (!out) throw DataError(fmt::format("{}: cannot write", path));
}

std::string OutputLabel(const Actuator& a) {
  return a.output.unit == "N" ? "Force F [N]" : "Output y";
}
std::string InputLabel(const Actuator& a) {
  return a.input.unit == "%" ? "Duty cycle u [%]" : "Input u";
}

// The experiment with the chosen model simulated on it (held-out part last).
void WriteModelFigures(const CommissionResult& r, const Actuator& act,
                       const std::filesystem::path& dir, CommissionFiles& files) {
  for (const IdentifiedModel& m : r.identification.models) {
    if (m.method != r.chosen_model) continue;
    NamedModel nm{m.method + " (" + m.structure + ")", m.discrete ? *m.discrete : m.tf, m.u0, m.y0,
                  std::make_shared<const IdentifiedModel>(m)};
    ComparisonFigureOptions fo;
    fo.labels.output = OutputLabel(act);
    fo.labels.input = InputLabel(act);
    fo.title = "commission: estimation sequence and the chosen model";
    ModelComparisonFigure(r.experiment.estimation, {nm}, fo)
        .Save((dir / "experiment.png").string());
    files.written.push_back((dir / "experiment.png").string());
    fo.title = "commission: held-out sequence and the chosen model";
    ModelComparisonFigure(r.experiment.validation, {nm}, fo)
        .Save((dir / "validation.png").string());
    files.written.push_back((dir / "validation.png").string());
  }
}

}  // namespace

bool CommissionFilesOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error != nullptr) *error = m;
    return false;
  };
  if (directory.empty()) return fail("directory is empty");
  if (!(Ts > 0.0) || !std::isfinite(Ts))
    return fail(fmt::format("Ts must be positive, got {}", Ts));
  if (io.empty()) return fail("io is empty (expected sim, udp://HOST:PORT or comedi)");
  if (io == "sim" && plant.empty()) return fail("plant is empty with io = sim");
  return true;
}

nlohmann::ordered_json CommissionFiles::ToJson() const {
  nlohmann::ordered_json j;
  j["written"] = written;
  j["c_module"] = c_module;
  return j;
}

CommissionFiles WriteCommissionFiles(const CommissionResult& r, const Actuator& act,
                                     const CommissionFilesOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid commission files options: {}", error);
  const std::filesystem::path dir(o.directory);
  CommissionFiles files;
  if (r.experiment.data.size() > 0) {
    WriteCsv(r.experiment.data, (dir / "data.csv").string());
    files.written.push_back((dir / "data.csv").string());
  }
  WriteModelFigures(r, act, dir, files);
  if (!r.attempts.empty()) {
    const ClosedLoopResult& cl = r.attempts.back().result;
    WriteVerificationCsv((dir / "verification.csv").string(), cl);
    files.written.push_back((dir / "verification.csv").string());
    WriteControllerToml((dir / "controller.toml").string(), r, o);
    files.written.push_back((dir / "controller.toml").string());
    ClosedLoopFigureOptions options;
    options.labels.time = "Time t [s]";
    options.labels.output = OutputLabel(act);
    options.labels.input = InputLabel(act);
    options.title = fmt::format("verification: {} on {} ({})", r.settings.controller,
                                PlotLiteral(r.chosen_model), r.passed() ? "pass" : "fail");
    ClosedLoopFigure(cl.t, cl.r, {{r.settings.controller, cl.y, cl.u}}, options)
        .Save((dir / "verification.png").string());
    files.written.push_back((dir / "verification.png").string());
  }
  if (o.report) {
    WriteCommissionReport(r, o.plant_description, act.input, act.output,
                          (dir / "report.html").string());
    files.written.push_back((dir / "report.html").string());
  }
  // The C module of the final design (pneumid codegen): DIR/c.
  if (o.c_module && !r.attempts.empty()) {
    try {
      const BuiltController built =
          MakeController(ParseControllerModel(r.controller_model), o.Ts,
                         WithModelInputMap(ToControllerSpec(r.settings), r.controller_model));
      const CodegenResult code = GenerateC(*built.controller, CodegenOptions{});
      for (const std::string& f : WriteCodegenFiles(code, (dir / "c").string()))
        files.written.push_back(f);
      files.c_module = (dir / "c").string();
    } catch (const std::exception& e) {
      files.c_module = std::string("not written: ") + e.what();
    }
  }
  return files;
}

}  // namespace pneumid
