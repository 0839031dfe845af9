#include "pneumid/report/plot.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>

#include <plplot/plstream.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/report/html.hpp"

namespace pneumid {

namespace {

// PLplot's predefined line styles (pllsty): 1 continuous, 2 short dashes,
// 3 long dashes.
int PlStyle(LineStyle s) {
  switch (s) {
    case LineStyle::kSolid:
      return 1;
    case LineStyle::kDashed:
      return 3;
    case LineStyle::kDotted:
      return 2;
  }
  return 1;
}

// Colour map 0 layout used by the renderer.
constexpr int kBackground = 0;
constexpr int kForeground = 1;
constexpr int kGridColor = 2;
constexpr int kFirstFree = 3;
constexpr int kMapSize = 256;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool Valid() const { return lo <= hi; }
};

double Tx(const Axes& ax, double x) { return ax.log_x ? std::log10(x) : x; }
bool UsableX(const Axes& ax, double x) { return std::isfinite(x) && (!ax.log_x || x > 0.0); }

// Data ranges of one subplot: x over series and bands, y over everything.
void ComputeLimits(const Axes& ax, double* xmin, double* xmax, double* ymin, double* ymax) {
  Range xr, yr;
  for (const auto& s : ax.series) {
    for (Eigen::Index i = 0; i < s.x.size(); ++i) {
      if (!UsableX(ax, s.x[i]) || !std::isfinite(s.y[i])) continue;
      xr.Add(Tx(ax, s.x[i]));
      yr.Add(s.y[i]);
    }
  }
  for (const auto& b : ax.bands) {
    for (Eigen::Index i = 0; i < b.x.size(); ++i) {
      if (!UsableX(ax, b.x[i])) continue;
      xr.Add(Tx(ax, b.x[i]));
      yr.Add(b.lower[i]);
      yr.Add(b.upper[i]);
    }
  }
  for (const auto& h : ax.hlines) yr.Add(h.y);
  if (!xr.Valid()) xr = Range{0.0, 1.0};
  if (!yr.Valid()) yr = Range{0.0, 1.0};
  if (xr.hi - xr.lo <= 0.0) {
    xr.lo -= 0.5;
    xr.hi += 0.5;
  }
  double span = yr.hi - yr.lo;
  if (span <= 1e-12 * std::max(1.0, std::abs(yr.hi))) {
    const double pad = std::max(1.0, 0.1 * std::abs(yr.hi));
    yr.lo -= pad;
    yr.hi += pad;
  } else {
    yr.lo -= 0.05 * span;
    yr.hi += 0.05 * span;
  }
  *xmin = ax.xmin ? Tx(ax, *ax.xmin) : xr.lo;
  *xmax = ax.xmax ? Tx(ax, *ax.xmax) : xr.hi;
  *ymin = ax.ymin ? *ax.ymin : yr.lo;
  *ymax = ax.ymax ? *ax.ymax : yr.hi;
  if (*xmax <= *xmin) *xmax = *xmin + 1.0;
  if (*ymax <= *ymin) *ymax = *ymin + 1.0;
}

void CheckXY(const Eigen::VectorXd& x, const Eigen::VectorXd& y, const char* what) {
  PNEUMID_CHECK(x.size() == y.size(), "{}: x and y must have the same length, got {} and {}", what,
                x.size(), y.size());
  PNEUMID_CHECK(x.size() > 0, "{}: empty data", what);
}

struct LegendEntry {
  int opt = PL_LEGEND_LINE;
  std::string text;
  int color = kForeground;
  int style = 1;
  double width = 2.0;
};

class Renderer {
 public:
  Renderer(const Figure& fig, const std::string& path, ImageFormat format)
      : fig_(fig), path_(path), format_(format) {}

  void Run() {
    const FigureOptions& o = fig_.options();
    const int rows = fig_.rows();
    const int per = o.height_per_axes > 0 ? o.height_per_axes : (rows == 1 ? 420 : 330);
    const int height = per * rows + (fig_.title.empty() ? 0 : 40);
    plstream pls;
    pls.sdev(format_ == ImageFormat::kPng ? "pngcairo" : "svgcairo");
    pls.sfnam(path_.c_str());
    const std::string geometry = std::to_string(o.width) + "x" + std::to_string(height);
    pls.setopt("geometry", geometry.c_str());
    pls.scmap0n(kMapSize);
    pls.scol0(kBackground, 255, 255, 255);
    pls.scol0(kForeground, 0, 0, 0);
    pls.scol0(kGridColor, 215, 215, 215);
    pls.sfci(0);
    pls.init();
    pls.adv(0);
    pls.schr(0.0, 0.95 * o.font_scale);

    // Layout in normalized subpage coordinates: equal panels, a top strip for
    // the figure title, room left for the y label and below for the x label.
    const double top = fig_.title.empty() ? 0.97 : 1.0 - 55.0 / height;
    const double bottom = 0.0;
    const double panel = (top - bottom) / rows;
    const double left = 0.085 * 960.0 / std::max(400, o.width) + 0.01;
    const double right = 0.96;
    next_color_ = kFirstFree;
    for (int r = 0; r < rows; ++r) {
      const Axes& ax = fig_.axes(r);
      const double hi = top - r * panel - (ax.title.empty() ? 6.0 : 30.0) / height;
      const double lo = top - (r + 1) * panel + (ax.xlabel.empty() ? 40.0 : 74.0) / height;
      DrawAxes(pls, ax, left, right, lo, hi);
      if (r == 0 && !fig_.title.empty()) {
        pls.col0(kForeground);
        pls.schr(0.0, 1.2 * o.font_scale);
        pls.mtex("t", ax.title.empty() ? 1.4 : 3.2, 0.5, 0.5, fig_.title.c_str());
        pls.schr(0.0, 0.95 * o.font_scale);
      }
    }
    // plstream's destructor ends the stream and flushes the file.
  }

 private:
  int NewColor(const Color& c, double alpha, plstream& pls) {
    const int idx = next_color_;
    next_color_ = next_color_ + 1 < kMapSize ? next_color_ + 1 : kFirstFree;
    pls.scol0a(idx, std::clamp(c.r, 0, 255), std::clamp(c.g, 0, 255), std::clamp(c.b, 0, 255),
               std::clamp(alpha, 0.0, 1.0));
    return idx;
  }

  void DrawAxes(plstream& pls, const Axes& ax, double left, double right, double lo, double hi) {
    double xmin, xmax, ymin, ymax;
    ComputeLimits(ax, &xmin, &xmax, &ymin, &ymax);
    pls.vpor(left, right, lo, hi);
    pls.wind(xmin, xmax, ymin, ymax);
    const std::string xlog = ax.log_x ? "l" : "";
    std::vector<LegendEntry> legend;

    // Bands underneath everything else.
    for (const auto& b : ax.bands) {
      std::vector<double> px, py;
      for (Eigen::Index i = 0; i < b.x.size(); ++i) {
        if (!UsableX(ax, b.x[i])) continue;
        px.push_back(Tx(ax, b.x[i]));
        py.push_back(std::clamp(b.upper[i], ymin, ymax));
      }
      for (Eigen::Index i = b.x.size() - 1; i >= 0; --i) {
        if (!UsableX(ax, b.x[i])) continue;
        px.push_back(Tx(ax, b.x[i]));
        py.push_back(std::clamp(b.lower[i], ymin, ymax));
      }
      if (px.size() < 2) continue;
      const std::size_t half = px.size() / 2;
      if (b.shaded) {
        const int fill = NewColor(b.color, b.alpha, pls);
        pls.col0(fill);
        pls.psty(0);
        pls.fill(static_cast<PLINT>(px.size()), px.data(), py.data());
        if (!b.label.empty()) {
          LegendEntry e;
          e.opt = PL_LEGEND_COLOR_BOX;
          e.text = b.label;
          e.color = fill;
          legend.push_back(e);
        }
      } else {
        const int col = NewColor(b.color, 1.0, pls);
        pls.col0(col);
        pls.lsty(PlStyle(LineStyle::kDashed));
        pls.width(1.5);
        pls.line(static_cast<PLINT>(half), px.data(), py.data());
        pls.line(static_cast<PLINT>(px.size() - half), px.data() + half, py.data() + half);
        if (!b.label.empty()) legend.push_back({PL_LEGEND_LINE, b.label, col, 3, 1.5});
      }
    }

    if (ax.grid) {
      pls.col0(kGridColor);
      pls.lsty(1);
      pls.width(0.6);
      pls.box(("g" + xlog).c_str(), 0.0, 0, "g", 0.0, 0);
    }

    int palette = 0;
    for (const auto& s : ax.series) {
      const Color c = s.color ? *s.color : PaletteColor(palette++);
      const int col = NewColor(c, 1.0, pls);
      std::vector<double> px, py;
      px.reserve(s.x.size() * (s.stairs ? 2 : 1));
      py.reserve(px.capacity());
      auto flush = [&]() {
        if (px.size() >= 2) pls.line(static_cast<PLINT>(px.size()), px.data(), py.data());
        px.clear();
        py.clear();
      };
      pls.col0(col);
      pls.lsty(PlStyle(s.style));
      pls.width(s.width);
      for (Eigen::Index i = 0; i < s.x.size(); ++i) {
        if (!UsableX(ax, s.x[i]) || !std::isfinite(s.y[i])) {
          flush();  // gaps at NaN
          continue;
        }
        const double x = Tx(ax, s.x[i]);
        if (s.stairs && !py.empty()) {
          px.push_back(x);
          py.push_back(py.back());
        }
        px.push_back(x);
        py.push_back(s.y[i]);
      }
      flush();
      if (!s.label.empty())
        legend.push_back({PL_LEGEND_LINE, s.label, col, PlStyle(s.style), s.width});
    }

    for (const auto& h : ax.hlines) {
      const int col = NewColor(h.color, 1.0, pls);
      pls.col0(col);
      pls.lsty(PlStyle(h.style));
      pls.width(1.5);
      pls.join(xmin, h.y, xmax, h.y);
      if (!h.label.empty()) legend.push_back({PL_LEGEND_LINE, h.label, col, PlStyle(h.style), 1.5});
    }

    pls.lsty(1);
    pls.width(1.0);
    pls.col0(kForeground);
    pls.box(("bcnst" + xlog).c_str(), 0.0, 0, "bcnstv", 0.0, 0);
    pls.lab(ax.xlabel.c_str(), ax.ylabel.c_str(), "");
    if (!ax.title.empty()) pls.mtex("t", 1.0, 0.5, 0.5, ax.title.c_str());

    if (!legend.empty() && ax.legend != LegendPosition::kNone) DrawLegend(pls, ax, legend);
  }

  void DrawLegend(plstream& pls, const Axes& ax, const std::vector<LegendEntry>& entries) {
    PLINT position = PL_POSITION_INSIDE | PL_POSITION_VIEWPORT;
    switch (ax.legend) {
      case LegendPosition::kTopRight:
        position |= PL_POSITION_TOP | PL_POSITION_RIGHT;
        break;
      case LegendPosition::kBottomRight:
        position |= PL_POSITION_BOTTOM | PL_POSITION_RIGHT;
        break;
      case LegendPosition::kTopLeft:
        position |= PL_POSITION_TOP | PL_POSITION_LEFT;
        break;
      case LegendPosition::kBottomLeft:
        position |= PL_POSITION_BOTTOM | PL_POSITION_LEFT;
        break;
      case LegendPosition::kNone:
        return;
    }
    const auto n = entries.size();
    std::vector<PLINT> opt(n), text_colors(n, kForeground), box_colors(n), box_patterns(n, 0),
        line_colors(n), line_styles(n), symbol_colors(n, kForeground), symbol_numbers(n, 0);
    std::vector<PLFLT> box_scales(n, 0.9), box_widths(n, 1.0), line_widths(n),
        symbol_scales(n, 1.0);
    std::vector<const char*> text(n), symbols(n, "");
    for (std::size_t i = 0; i < n; ++i) {
      opt[i] = entries[i].opt;
      text[i] = entries[i].text.c_str();
      box_colors[i] = entries[i].color;
      line_colors[i] = entries[i].color;
      line_styles[i] = entries[i].style;
      line_widths[i] = entries[i].width;
    }
    PLFLT w = 0.0, h = 0.0;
    pls.lsty(1);
    pls.legend(&w, &h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, position, 0.015, 0.03, 0.07,
               kBackground, kForeground, 1, 0, 0, static_cast<PLINT>(n), opt.data(), 0.8, 0.85, 1.8,
               0.0, text_colors.data(), text.data(), box_colors.data(), box_patterns.data(),
               box_scales.data(), box_widths.data(), line_colors.data(), line_styles.data(),
               line_widths.data(), symbol_colors.data(), symbol_scales.data(),
               symbol_numbers.data(), symbols.data());
  }

  const Figure& fig_;
  std::string path_;
  ImageFormat format_;
  int next_color_ = kFirstFree;
};

std::mutex& PlplotMutex() {
  static std::mutex m;  // PLplot keeps global state
  return m;
}

void ReplaceAll(std::string* s, const std::string& from, const std::string& to) {
  std::size_t pos = 0;
  while ((pos = s->find(from, pos)) != std::string::npos) {
    s->replace(pos, from.size(), to);
    pos += to.size();
  }
}

// Removes PLplot's escape sequences (#u, #d, ##) for plain-text descriptions.
std::string PlainText(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '#' && i + 1 < s.size()) {
      if (s[i + 1] == '#') out += '#';
      ++i;
      continue;
    }
    out += s[i];
  }
  return out;
}

}  // namespace

std::string DescribeFigure(const Figure& figure);

std::string PlotLiteral(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    out += ch;
    if (ch == '#') out += '#';
  }
  return out;
}

namespace {

// Accessible text: <title> and <desc> after the opening <svg ...> tag (cairo
// draws text as glyph outlines, so the labels are not otherwise searchable).
void AddSvgMetadata(const Figure& fig, std::string* svg) {
  const auto open = svg->find("<svg");
  if (open == std::string::npos) return;
  const auto close_tag = svg->find('>', open);
  if (close_tag == std::string::npos) return;
  const std::string title = PlainText(!fig.title.empty() ? fig.title : fig.axes(0).title);
  const std::string meta = "\n<title>" + HtmlEscape(title) + "</title>\n<desc>" +
                           HtmlEscape(DescribeFigure(fig)) + "</desc>";
  svg->insert(close_tag + 1, meta);
  svg->insert(open + 4, " role=\"img\"");
}

}  // namespace

namespace {
constexpr EnumName<LineStyle> kLineStyleNames[] = {
    {LineStyle::kSolid, "solid"},
    {LineStyle::kDashed, "dashed"},
    {LineStyle::kDotted, "dotted"},
};
}  // namespace

std::string ToString(LineStyle v) { return std::string(EnumToString(kLineStyleNames, v)); }

LineStyle LineStyleFromString(const std::string& name) {
  return EnumFromString(kLineStyleNames, name, "line style", /*ignore_case=*/true);
}

namespace {
constexpr EnumName<ImageFormat> kImageFormatNames[] = {
    {ImageFormat::kPng, "png"},
    {ImageFormat::kSvg, "svg"},
};
}  // namespace

std::string ToString(ImageFormat v) { return std::string(EnumToString(kImageFormatNames, v)); }

ImageFormat ImageFormatFromString(const std::string& name) {
  return EnumFromString(kImageFormatNames, name, "image format", /*ignore_case=*/true);
}

ImageFormat ImageFormatFromPath(const std::string& path) {
  const std::string ext = ToLower(std::filesystem::path(path).extension().string());
  PNEUMID_CHECK(ext == ".png" || ext == ".svg",
                "cannot tell the image format of '{}': the file name must end in .png or .svg",
                path);
  return ext == ".png" ? ImageFormat::kPng : ImageFormat::kSvg;
}

Color PaletteColor(int i) {
  // Tableau 10 (matplotlib's default cycle), colour-blind friendly ordering.
  static const std::array<Color, 10> kPalette = {{{31, 119, 180},
                                                  {214, 39, 40},
                                                  {44, 160, 44},
                                                  {255, 127, 14},
                                                  {148, 103, 189},
                                                  {140, 86, 75},
                                                  {227, 119, 194},
                                                  {127, 127, 127},
                                                  {188, 189, 34},
                                                  {23, 190, 207}}};
  const int n = static_cast<int>(kPalette.size());
  return kPalette[((i % n) + n) % n];
}

Curve& Axes::AddLine(const Eigen::VectorXd& x, const Eigen::VectorXd& y, std::string label,
                     LineStyle style) {
  CheckXY(x, y, "Axes::AddLine");
  Curve s;
  s.x = x;
  s.y = y;
  s.label = std::move(label);
  s.style = style;
  series.push_back(std::move(s));
  return series.back();
}

Curve& Axes::AddStairs(const Eigen::VectorXd& x, const Eigen::VectorXd& y, std::string label) {
  CheckXY(x, y, "Axes::AddStairs");
  Curve& s = AddLine(x, y, std::move(label));
  s.stairs = true;
  return s;
}

HorizontalLine& Axes::AddHorizontalLine(double y, std::string label, LineStyle style) {
  PNEUMID_CHECK(std::isfinite(y), "Axes::AddHorizontalLine: y must be finite, got {}", y);
  HorizontalLine h;
  h.y = y;
  h.label = std::move(label);
  h.style = style;
  hlines.push_back(std::move(h));
  return hlines.back();
}

Band& Axes::AddBand(const Eigen::VectorXd& x, const Eigen::VectorXd& lower,
                    const Eigen::VectorXd& upper, std::string label, bool shaded) {
  CheckXY(x, lower, "Axes::AddBand (lower)");
  CheckXY(x, upper, "Axes::AddBand (upper)");
  Band b;
  b.x = x;
  b.lower = lower;
  b.upper = upper;
  b.label = std::move(label);
  b.shaded = shaded;
  bands.push_back(std::move(b));
  return bands.back();
}

bool FigureOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (width < 200 || width > 8000)
    return fail("FigureOptions::width must be in [200, 8000] pixels, got " + std::to_string(width));
  if (height_per_axes != 0 && (height_per_axes < 100 || height_per_axes > 4000))
    return fail("FigureOptions::height_per_axes must be 0 or in [100, 4000], got " +
                std::to_string(height_per_axes));
  if (!(font_scale > 0.1 && font_scale < 10.0))
    return fail("FigureOptions::font_scale must be in (0.1, 10), got " +
                std::to_string(font_scale));
  return true;
}

Figure::Figure(int rows, FigureOptions options) : options_(options) {
  PNEUMID_CHECK(rows >= 1 && rows <= 3, "a figure has 1 to 3 subplots, got rows = {}", rows);
  axes_.resize(static_cast<std::size_t>(rows));
}

Axes& Figure::axes(int i) {
  PNEUMID_CHECK(i >= 0 && i < rows(), "subplot index {} out of range [0, {})", i, rows());
  return axes_[static_cast<std::size_t>(i)];
}

const Axes& Figure::axes(int i) const {
  PNEUMID_CHECK(i >= 0 && i < rows(), "subplot index {} out of range [0, {})", i, rows());
  return axes_[static_cast<std::size_t>(i)];
}

void Figure::Save(const std::string& path) const { Save(path, ImageFormatFromPath(path)); }

void Figure::Save(const std::string& path, ImageFormat format) const {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "{}", error);
  bool any = false;
  for (const auto& ax : axes_) any = any || !ax.series.empty() || !ax.bands.empty();
  PNEUMID_CHECK(any, "cannot save '{}': the figure has no data", path);
  for (const auto& ax : axes_) {
    if (!ax.log_x) continue;
    bool positive = false;
    for (const auto& s : ax.series) positive = positive || (s.x.array() > 0.0).any();
    PNEUMID_CHECK(positive || ax.series.empty(),
                  "cannot save '{}': a logarithmic x axis needs positive x values", path);
  }
  // PLplot ends the process when it cannot open its output file; check first.
  {
    std::ofstream probe(path, std::ios::binary | std::ios::trunc);
    if (!probe) throw DataError(path + ": cannot open the file for writing");
  }
  std::lock_guard<std::mutex> lock(PlplotMutex());
  Renderer(*this, path, format).Run();
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) == 0 || ec)
    throw DataError(path + ": PLplot wrote no image");
  if (format == ImageFormat::kSvg) {
    std::string svg;
    {
      std::ifstream in(path, std::ios::binary);
      std::ostringstream ss;
      ss << in.rdbuf();
      svg = ss.str();
    }
    AddSvgMetadata(*this, &svg);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << svg;
    if (!out) throw DataError(path + ": write failed");
  }
}

std::string Figure::ToSvg(const std::string& id_prefix) const {
  std::string tmpl = (std::filesystem::temp_directory_path() / "pneumid-plot-XXXXXX.svg").string();
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const int fd = mkstemps(name.data(), 4);
  if (fd < 0) throw DataError(tmpl + ": cannot create a temporary file");
  close(fd);
  const std::string path(name.data());
  std::string svg;
  try {
    Save(path, ImageFormat::kSvg);
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    svg = ss.str();
  } catch (...) {
    std::remove(path.c_str());
    throw;
  }
  std::remove(path.c_str());

  // Drop the XML prolog so that the document can be inlined in HTML.
  if (svg.rfind("<?xml", 0) == 0) {
    const auto end = svg.find("?>");
    if (end != std::string::npos) svg.erase(0, svg.find_first_not_of(" \r\n", end + 2));
  }
  // Unique ids per figure (cairo names glyphs "glyph0-1", clips "clip1", ...).
  const std::string p = id_prefix + "-";
  ReplaceAll(&svg, "id=\"", "id=\"" + p);
  ReplaceAll(&svg, "href=\"#", "href=\"#" + p);
  ReplaceAll(&svg, "url(#", "url(#" + p);
  return svg;
}

std::string DescribeFigure(const Figure& figure) {
  std::ostringstream os;
  if (!figure.title.empty()) os << PlainText(figure.title) << "\n";
  for (int r = 0; r < figure.rows(); ++r) {
    const Axes& ax = figure.axes(r);
    if (!ax.title.empty()) os << "subplot " << r + 1 << ": " << PlainText(ax.title) << "\n";
    if (!ax.xlabel.empty()) os << "x: " << PlainText(ax.xlabel) << "\n";
    if (!ax.ylabel.empty()) os << "y: " << PlainText(ax.ylabel) << "\n";
    for (const auto& s : ax.series)
      if (!s.label.empty()) os << "line: " << PlainText(s.label) << "\n";
    for (const auto& h : ax.hlines)
      if (!h.label.empty()) os << "reference: " << PlainText(h.label) << "\n";
    for (const auto& b : ax.bands)
      if (!b.label.empty()) os << "band: " << PlainText(b.label) << "\n";
  }
  return os.str();
}

}  // namespace pneumid
