// Figures: a small plotting API on top of PLplot's cairo driver.
//
// A Figure holds 1..3 subplots stacked vertically that share the page width.
// Each subplot (Axes) holds line series with legend labels, horizontal
// reference lines (set-points, limits) and confidence bands (shaded areas or
// dashed bounds), axis labels with units, a title and a grid. A figure is
// written as PNG ("pngcairo") or SVG ("svgcairo"), chosen by the file
// extension, or rendered to an in-memory SVG string for HTML reports.
//
//   pneumid::Figure fig(2);
//   fig.title = "Closed loop";
//   auto& ax = fig.axes(0);
//   ax.ylabel = "Force F [N]";
//   ax.AddLine(t, y, "output");
//   ax.AddHorizontalLine(100.0, "set-point", pneumid::LineStyle::kDashed);
//   fig.axes(1).AddStairs(t, u, "duty cycle");
//   fig.Save("loop.png");
//
// Text uses PLplot's escape sequences: "#u" / "#d" start super- / subscripts
// and "##" prints a literal '#'. Labels are plain text otherwise.
// [1] PLplot 5.15 reference manual, plstream API (plenv, plbox, pllegend, plfill).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace pneumid {

/// Line styles (PLplot plstyl patterns 1..3).
enum class LineStyle { kSolid, kDashed, kDotted };
/// "solid", "dashed", "dotted".
std::string ToString(LineStyle style);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
LineStyle LineStyleFromString(const std::string& name);

/// Output formats of Figure::Save.
enum class ImageFormat { kPng, kSvg };
/// "png", "svg".
std::string ToString(ImageFormat format);
/// Inverse of ToString (case-insensitive); throws InvalidArgument.
ImageFormat ImageFormatFromString(const std::string& name);
/// Format implied by a file name's extension (.png, .svg; case-insensitive).
/// Throws InvalidArgument for any other extension.
ImageFormat ImageFormatFromPath(const std::string& path);

/// An RGB colour, components 0..255.
struct Color {
  int r = 0,  ///< red, 0..255
      g = 0,  ///< green, 0..255
      b = 0;  ///< blue, 0..255
};
/// The i-th colour of the default palette (Tableau 10; wraps around).
Color PaletteColor(int i);

/// One curve y(x) of a subplot. `label` empty = not listed in the legend.
/// (Named Curve, not Series: pneumid::Series is the series connection of two
/// transfer functions, pneumid/lti/interconnect.hpp.)
struct Curve {
  Eigen::VectorXd x;                    ///< abscissae in x-axis units (e.g. s), same length as y
  Eigen::VectorXd y;                    ///< ordinates in y-axis units (e.g. N)
  std::string label;                    ///< legend entry; empty: not listed
  LineStyle style = LineStyle::kSolid;  ///< solid, dashed or dotted
  std::optional<Color> color;           ///< default: next palette colour of its axes
  double width = 2.0;                   ///< line width in PLplot units (about pixels / 1)
  bool stairs = false;                  ///< drawn as a zero-order-hold staircase
};

/// A horizontal reference line at y (set-point, confidence limit, ...).
struct HorizontalLine {
  double y = 0.0;                        ///< level, y-axis units
  std::string label;                     ///< legend entry; empty: not listed
  LineStyle style = LineStyle::kDashed;  ///< line style (dashed by default)
  Color color{90, 90, 90};               ///< line colour (grey by default)
};

/// A band lower(x) <= y <= upper(x): a translucent shaded area (`shaded`) or
/// two dashed bounds.
struct Band {
  Eigen::VectorXd x;          ///< abscissae, same length as lower and upper
  Eigen::VectorXd lower;      ///< lower bound at each x, y-axis units
  Eigen::VectorXd upper;      ///< upper bound at each x, y-axis units
  std::string label;          ///< legend entry; empty: not listed
  bool shaded = true;         ///< filled area; false: two dashed bound lines
  Color color{31, 119, 180};  ///< fill or line colour (palette blue by default)
  double alpha = 0.25;        ///< fill opacity 0..1 (shaded bands)
};

/// Legend placement inside the axes.
enum class LegendPosition { kNone, kTopRight, kBottomRight, kTopLeft, kBottomLeft };

/// One subplot.
struct Axes {
  std::string title;   ///< subplot title; empty: none
  std::string xlabel;  ///< with unit, e.g. "Time t [s]"
  std::string ylabel;  ///< with unit, e.g. "Force F [N]"
  bool grid = true;    ///< draw grid lines at the major ticks
  bool log_x = false;  ///< logarithmic x axis (Bode plots); x values must be > 0
  LegendPosition legend = LegendPosition::kBottomRight;  ///< kNone: no legend
  /// Axis limits; unset = data range (y with a 5 % margin).
  std::optional<double> xmin,
      xmax,  ///< upper x limit; unset = data range
      ymin,  ///< lower y limit; unset = data range with a 5 % margin
      ymax;  ///< upper y limit; unset = data range with a 5 % margin

  std::vector<Curve> series;           ///< curves, drawn in order
  std::vector<HorizontalLine> hlines;  ///< horizontal reference lines
  std::vector<Band> bands;             ///< bands, drawn beneath the curves

  /// Adds a line. Throws InvalidArgument when x and y differ in length or are
  /// empty. Returns the new series for further styling.
  Curve& AddLine(const Eigen::VectorXd& x, const Eigen::VectorXd& y, std::string label = {},
                 LineStyle style = LineStyle::kSolid);
  /// Adds a zero-order-hold staircase (sampled inputs). Same checks as AddLine.
  Curve& AddStairs(const Eigen::VectorXd& x, const Eigen::VectorXd& y, std::string label = {});
  /// Adds a horizontal reference line (dashed by default).
  HorizontalLine& AddHorizontalLine(double y, std::string label = {},
                                    LineStyle style = LineStyle::kDashed);
  /// Adds a confidence band; throws InvalidArgument when the lengths differ.
  Band& AddBand(const Eigen::VectorXd& x, const Eigen::VectorXd& lower,
                const Eigen::VectorXd& upper, std::string label = {}, bool shaded = true);
};

/// Page options of a figure.
struct FigureOptions {
  int width = 960;          ///< pixels (PNG) / points (SVG)
  int height_per_axes = 0;  ///< pixels per subplot; 0 = 420 for one, 330 for more
  double font_scale = 1.0;  ///< multiplies PLplot's default character height
  /// True for width in [200, 8000], height_per_axes 0 or in [100, 4000] and font_scale
  /// in (0.1, 10); otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// A figure of 1..3 stacked subplots (Axes), written as PNG or SVG through PLplot.
class Figure {
 public:
  /// A figure with `rows` stacked subplots (1..3). Throws InvalidArgument otherwise.
  explicit Figure(int rows = 1, FigureOptions options = {});

  int rows() const { return static_cast<int>(axes_.size()); }  ///< number of subplots
  /// Subplot i (0 = top). Throws InvalidArgument when out of range.
  Axes& axes(int i);
  const Axes& axes(int i) const;                             ///< read-only axes(i)
  FigureOptions& options() { return options_; }              ///< page size and font scale
  const FigureOptions& options() const { return options_; }  ///< page size and font scale

  /// Figure title drawn above the first subplot.
  std::string title;

  /// Writes the figure to `path`, PNG or SVG by extension (ImageFormatFromPath).
  /// Throws InvalidArgument for an unknown extension, an empty figure or invalid
  /// options, and DataError when the file cannot be written.
  void Save(const std::string& path) const;
  /// Writes the figure in the given format regardless of the extension.
  void Save(const std::string& path, ImageFormat format) const;
  /// The figure as an SVG document (no XML prolog). Element ids are prefixed
  /// with `id_prefix` so that several figures can be inlined in one HTML page.
  /// The SVG carries `<title>` and `<desc>` elements listing the title, axis labels
  /// and legend entries (text is drawn as glyph outlines by cairo).
  std::string ToSvg(const std::string& id_prefix = "fig") const;

 private:
  std::vector<Axes> axes_;
  FigureOptions options_;
};

/// `text` for a title, label or legend entry, with PLplot's escape character
/// '#' doubled, so that user text such as "models.json#fit-p1d" is drawn as
/// written (a lone '#' starts an escape: `#u` superscript, `#f` font, ...).
std::string PlotLiteral(const std::string& text);

/// Plain-text description of a figure (title, axis labels, legend entries),
/// one item per line; used for the SVG `<desc>` element and the HTML alt text.
std::string DescribeFigure(const Figure& figure);

}  // namespace pneumid
