// Tests of the HTML identification report (include/pneumid/report/
// identification_report.hpp, html.hpp): names from the data (file name,
// channel names) are escaped wherever they appear, and the page holds the
// documented sections, tables and a row per model.
#include "pneumid/report/identification_report.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/report/html.hpp"

namespace pneumid {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

fs::path OutDir(const std::string& name) {
  fs::path d = fs::path(PNEUMID_BINARY_DIR) / "test-output" / "html_report" / name;
  fs::remove_all(d);
  return d;
}

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto i = text.find(what); i != std::string::npos; i = text.find(what, i + what.size())) ++n;
  return n;
}

// A first-order plant 2 / (0.3 s + 1), exact for the held input, sampled at
// Ts = 0.01 s, with a little seeded noise; the input is `levels`, each held
// for `dwell` samples.
Dataset FirstOrderRecord(const std::vector<double>& levels, int dwell, Channel input,
                         Channel output) {
  const double Ts = 0.01, a = std::exp(-Ts / 0.3), K = 2.0;
  const int n = static_cast<int>(levels.size()) * dwell;
  Eigen::VectorXd u(n), y(n);
  double x = 0.0;
  unsigned state = 12345;
  for (int k = 0; k < n; ++k) {
    u[k] = levels[k / dwell];
    state = state * 1103515245u + 12345u;  // deterministic noise of +-0.005
    y[k] = x + 0.01 * (static_cast<double>((state >> 16) & 0x7fff) / 32767.0 - 0.5);
    x = a * x + K * (1.0 - a) * u[k];
  }
  return Dataset::FromUniform(Ts, u, y, 0.0, std::move(input), std::move(output));
}

// Names with every character HTML gives a meaning: <, >, &, " and '.
const std::string kSource = "rigs/<A&B> \"step\" 'one'.csv";
const Channel kInput{"duty<u>&\"v\"", "%"};
const Channel kOutput{"force 'F'<y>", "N&m"};

TEST(HtmlReportTest, NamesFromTheDataAreEscaped) {
  Dataset data = FirstOrderRecord({0.0, 1.0}, 150, kInput, kOutput);
  data.set_source(kSource);
  ReportOptions o;
  o.methods = {"reaction-curve", "arx"};
  o.commands = {"pneumid report '" + kSource + "' --output-dir out"};
  const ReportSummary s = WriteIdentificationReport(data, o, OutDir("escaping").string());
  ASSERT_EQ(s.models.size(), 2u) << s.BriefReport();
  const std::string html = ReadFile(s.html_path);
  ASSERT_FALSE(html.empty());

  // The escaped forms are there: the file name in the title and the heading,
  // the source in the data table, the channels with their units, and the
  // reproducing command.
  const std::string file = "&lt;A&amp;B&gt; &quot;step&quot; &#39;one&#39;.csv";
  EXPECT_THAT(html, HasSubstr("<title>Identification report: " + file + "</title>"));
  EXPECT_THAT(html, HasSubstr("<h1>Identification report: " + file + "</h1>"));
  EXPECT_THAT(html, HasSubstr("<td>source</td><td>rigs/" + file + "</td>"));
  EXPECT_THAT(html, HasSubstr("<td>input</td><td>duty&lt;u&gt;&amp;&quot;v&quot; [%]</td>"));
  EXPECT_THAT(html, HasSubstr("<td>output</td><td>force &#39;F&#39;&lt;y&gt; [N&amp;m]</td>"));
  EXPECT_THAT(html, HasSubstr("<th>IAE [N&amp;m s]</th>"));
  EXPECT_THAT(html, HasSubstr("pneumid report &#39;rigs/" + file + "&#39; --output-dir out"));
  // The figures' accessible text (<desc>) names the axes, escaped too.
  EXPECT_THAT(html, HasSubstr("\ny: duty&lt;u&gt;&amp;&quot;v&quot; [%]\nline: input\n"));
  EXPECT_THAT(html, HasSubstr("\ny: force &#39;F&#39;&lt;y&gt; [N&amp;m]\n"));

  // ... and no raw form is: none of the names' pieces with a special
  // character occurs unescaped anywhere on the page (text, attributes, SVG).
  for (const std::string raw :
       {"<A&B>", "&B", "\"step\"", "'one'", "<u>", "&\"v", "\"v\"", "'F'", "<y>", "N&m"}) {
    EXPECT_THAT(html, Not(HasSubstr(raw))) << raw;
  }
}

TEST(HtmlReportTest, FailedMethodsAreListedEscaped) {
  // Two steps: the reaction curve refuses the record, naming the file.
  Dataset data = FirstOrderRecord({0.0, 1.0, 0.5}, 100, kInput, kOutput);
  data.set_source(kSource);
  ReportOptions o;
  o.methods = {"reaction-curve", "arx"};
  const ReportSummary s = WriteIdentificationReport(data, o, OutDir("failure").string());
  ASSERT_EQ(s.failures.size(), 1u) << s.BriefReport();
  EXPECT_EQ(s.failures[0].first, "reaction-curve");
  EXPECT_THAT(s.failures[0].second, HasSubstr(kSource));
  const std::string html = ReadFile(s.html_path);
  EXPECT_THAT(html, HasSubstr("<h3>Methods that gave no model</h3>"));
  EXPECT_THAT(html, HasSubstr("<li>reaction-curve: " + HtmlEscape(s.failures[0].second) + "</li>"));
  EXPECT_THAT(html, HasSubstr("<li>reaction-curve: rigs/&lt;A&amp;B&gt; &quot;step&quot;"));
  EXPECT_THAT(html, Not(HasSubstr("<A&B>")));
  EXPECT_THAT(html, Not(HasSubstr("\"step\"")));
}

TEST(HtmlReportTest, SectionsTablesFiguresAndOneRowPerModel) {
  Dataset data = FirstOrderRecord({0.0, 1.0}, 150, {"u", "%"}, {"F", "N"});
  data.set_source("step.csv");
  ReportOptions o;
  o.methods = {"reaction-curve", "arx", "fit-p1d"};
  o.commands = {"pneumid report step.csv -m reaction-curve,arx,fit-p1d --output-dir out"};
  const ReportSummary s = WriteIdentificationReport(data, o, OutDir("content").string());
  ASSERT_EQ(s.models.size(), 3u) << s.BriefReport();
  EXPECT_EQ(s.termination, Termination::kSuccess);
  EXPECT_TRUE(s.failures.empty());
  const std::string html = ReadFile(s.html_path);

  // A complete page: one <section> per level-2 heading, in this order.
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_THAT(html, HasSubstr("</html>"));
  const std::vector<std::string> headings = {"<h2>Data</h2>", "<h2>Models</h2>",
                                             "<h2>Figures</h2>", "<h2>Reproduce</h2>"};
  std::size_t at = 0;
  for (const std::string& h : headings) {
    const std::size_t i = html.find(h, at);
    ASSERT_NE(i, std::string::npos) << h << " missing or out of order";
    at = i;
  }
  EXPECT_EQ(Count(html, "<section>"), 4);
  EXPECT_EQ(Count(html, "</section>"), 4);
  EXPECT_THAT(html, Not(HasSubstr("Methods that gave no model")));
  // Three tables with their captions, four inline figures, as counted in the summary.
  EXPECT_EQ(s.num_tables, 3);
  EXPECT_EQ(Count(html, "<table class=\"data\">"), 3);
  EXPECT_THAT(html, HasSubstr("<caption>Dataset</caption>"));
  EXPECT_THAT(html, HasSubstr("<caption>Identified parameters</caption>"));
  EXPECT_THAT(html, HasSubstr(
                        "<caption>Fit to the data (model simulated on the measured input)</caption>"));
  EXPECT_EQ(s.num_figures, 4);
  EXPECT_EQ(Count(html, "<figure class=\"plot\"><svg"), 4);
  EXPECT_EQ(Count(html, "</svg>\n<figcaption>"), 4);
  EXPECT_THAT(html, HasSubstr("<title>Residuals of " + s.models[0].method + "</title>"));
  // The data table.
  EXPECT_THAT(html, HasSubstr("<td>source</td><td>step.csv</td>"));
  EXPECT_THAT(html, HasSubstr("<td>samples</td><td>300</td>"));
  EXPECT_THAT(html, HasSubstr("<td>sample time [s]</td><td>0.01</td>"));
  EXPECT_THAT(html, HasSubstr("<td>input</td><td>u [%]</td>"));
  EXPECT_THAT(html, HasSubstr("<td>output</td><td>F [N]</td>"));
  EXPECT_THAT(html, HasSubstr("<td>step</td><td>"));
  // Each model has one row in the parameter table and one in the fit table,
  // in the ranking's order, its fit printed with 5 significant digits.
  const std::size_t params = html.find("<caption>Identified parameters</caption>");
  const std::size_t fits = html.find("<caption>Fit to the data");
  ASSERT_LT(params, fits);
  std::size_t p_at = params, f_at = fits;
  for (const IdentifiedModel& m : s.models) {
    SCOPED_TRACE(m.method);
    const std::string p_row = "<tr><td>" + m.method + "</td><td>" + HtmlEscape(m.structure) + "</td>";
    EXPECT_EQ(Count(html, p_row), 1);
    const std::size_t p = html.find(p_row, p_at);
    ASSERT_NE(p, std::string::npos);
    EXPECT_LT(p, fits);
    p_at = p;
    const std::string f_row = fmt::format("<tr><td>{}</td><td>{:.5g}</td>", m.method, m.fit_percent);
    EXPECT_EQ(Count(html, f_row), 1);
    const std::size_t f = html.find(f_row, f_at);
    ASSERT_NE(f, std::string::npos);
    f_at = f;
    EXPECT_GT(m.fit_percent, 90.0);
  }
  // The tables hold as many rows as there are models (plus the data table's).
  EXPECT_EQ(Count(html, "<tr><td>reaction-curve</td>"), 2);
  EXPECT_EQ(Count(html, "<tr><td>arx</td>"), 2);
  EXPECT_EQ(Count(html, "<tr><td>fit-p1d</td>"), 2);
  // The reproducing command and the models file beside the page.
  EXPECT_THAT(html, HasSubstr("<pre class=\"commands\"><code>pneumid report step.csv -m "
                              "reaction-curve,arx,fit-p1d --output-dir out"));
  EXPECT_TRUE(fs::exists(s.models_path));
  // Nothing is loaded from elsewhere.
  EXPECT_THAT(html, Not(HasSubstr("<script")));
  EXPECT_THAT(html, Not(HasSubstr("src=\"http")));
}

TEST(HtmlReportTest, HtmlEscapeReplacesEverySpecialCharacter) {
  EXPECT_EQ(HtmlEscape("a<b>&\"c\"'d'"), "a&lt;b&gt;&amp;&quot;c&quot;&#39;d&#39;");
  EXPECT_EQ(HtmlEscape("&amp;"), "&amp;amp;");  // escaping is not idempotent: done once
  EXPECT_EQ(HtmlEscape("plain text 1.5 %"), "plain text 1.5 %");
}

}  // namespace
}  // namespace pneumid
