// Self-contained HTML documents: headings, paragraphs, tables, inline SVG
// figures and code blocks, with an embedded style sheet and no external
// resources (no scripts, fonts or images loaded from elsewhere), so that a
// report opens in any browser, offline, and can be mailed as one file.
//
// Structure of the generated page (stable, tests and scripts rely on it):
//   <main>  one <section> per heading level 2, in insertion order
//   <figure class="plot"> <svg ...> ... </svg> <figcaption> </figcaption> </figure>
//   <table class="data"> <caption> <thead> <tbody> </table>
//   <pre class="commands"><code> ... </code></pre>
#pragma once

#include <string>
#include <vector>

#include "pneumid/report/plot.hpp"

namespace pneumid {

/// A table of strings; every row must have header.size() cells.
struct Table {
  std::string caption;                         ///< text above the table (plain, escaped)
  std::vector<std::string> header;             ///< column titles, with units where needed
  std::vector<std::vector<std::string>> rows;  ///< cells, row by row (plain text, escaped)
  /// False (with a message) when a row's length differs from the header's or
  /// the header is empty.
  bool IsValid(std::string* error) const;
};

/// Escapes &, <, >, " and ' for HTML text and attribute values.
std::string HtmlEscape(const std::string& text);

/// A self-contained HTML page built block by block: headings, text, tables, inline
/// SVG figures and command listings.
class HtmlDocument {
 public:
  /// A document with the given `<title>` and top-level heading.
  explicit HtmlDocument(std::string title);

  /// Heading of level 2..4 (level 2 starts a new `<section>`).
  /// @throws InvalidArgument for another level.
  void AddHeading(const std::string& text, int level = 2);
  /// A paragraph of plain text (escaped).
  void AddParagraph(const std::string& text);
  /// A bulleted list of plain-text items (escaped).
  void AddList(const std::vector<std::string>& items);
  /// A table. @throws InvalidArgument when !table.IsValid().
  void AddTable(const Table& table);
  /// A figure rendered to inline SVG (ids prefixed per figure) with a caption.
  /// @throws as Figure::ToSvg.
  void AddFigure(const Figure& figure, const std::string& caption);
  /// A block of shell commands, one per line (escaped, monospace).
  void AddCommands(const std::vector<std::string>& lines);

  int num_figures() const { return num_figures_; }  ///< figures added so far
  int num_tables() const { return num_tables_; }    ///< tables added so far

  /// The complete page (`<!DOCTYPE html> ... </html>`).
  std::string Render() const;
  /// Writes Render() to `path`. @throws DataError when it cannot be written.
  void Write(const std::string& path) const;

 private:
  std::string title_;
  std::vector<std::string> blocks_;
  bool section_open_ = false;
  int num_figures_ = 0;
  int num_tables_ = 0;
};

}  // namespace pneumid
