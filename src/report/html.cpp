#include "pneumid/report/html.hpp"

#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/version.hpp"

namespace pneumid {

namespace {

constexpr const char* kStyle = R"css(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; margin: 0; color: #222;
       background: #fafafa; line-height: 1.45; }
header { background: #1f3b57; color: #fff; padding: 18px 32px; }
header h1 { margin: 0; font-size: 1.6em; }
header p { margin: 4px 0 0 0; color: #cfd8e3; font-size: 0.9em; }
main { max-width: 1040px; margin: 0 auto; padding: 8px 32px 40px 32px; }
section { background: #fff; border: 1px solid #e2e2e2; border-radius: 6px;
          padding: 4px 22px 16px 22px; margin: 18px 0; }
h2 { border-bottom: 2px solid #1f77b4; padding-bottom: 4px; font-size: 1.3em; }
h3 { font-size: 1.1em; }
figure.plot { margin: 14px 0; text-align: center; }
figure.plot svg { max-width: 100%; height: auto; border: 1px solid #eee; background: #fff; }
figcaption { font-size: 0.9em; color: #555; margin-top: 4px; }
table.data { border-collapse: collapse; margin: 12px 0; font-size: 0.92em; }
table.data caption { caption-side: top; text-align: left; font-weight: bold; padding: 4px 0; }
table.data th, table.data td { border: 1px solid #ccc; padding: 4px 10px; text-align: left; }
table.data th { background: #eef3f8; }
table.data tbody tr:nth-child(even) { background: #f7f7f7; }
pre.commands { background: #272822; color: #f8f8f2; padding: 10px 14px; border-radius: 4px;
               overflow-x: auto; font-size: 0.88em; }
footer { text-align: center; color: #888; font-size: 0.8em; padding: 12px; }
)css";

}  // namespace

bool Table::IsValid(std::string* error) const {
  if (header.empty()) {
    if (error) *error = "table '" + caption + "' has no header";
    return false;
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != header.size()) {
      if (error)
        *error = fmt::format("table '{}': row {} has {} cells, the header has {}", caption, i,
                             rows[i].size(), header.size());
      return false;
    }
  }
  return true;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

HtmlDocument::HtmlDocument(std::string title) : title_(std::move(title)) {}

void HtmlDocument::AddHeading(const std::string& text, int level) {
  PNEUMID_CHECK(level >= 2 && level <= 4, "heading level must be 2, 3 or 4, got {}", level);
  if (level == 2) {
    if (section_open_) blocks_.push_back("</section>");
    blocks_.push_back("<section>");
    section_open_ = true;
  }
  blocks_.push_back(fmt::format("<h{0}>{1}</h{0}>", level, HtmlEscape(text)));
}

void HtmlDocument::AddParagraph(const std::string& text) {
  blocks_.push_back("<p>" + HtmlEscape(text) + "</p>");
}

void HtmlDocument::AddList(const std::vector<std::string>& items) {
  std::string s = "<ul>";
  for (const auto& i : items) s += "<li>" + HtmlEscape(i) + "</li>";
  blocks_.push_back(s + "</ul>");
}

void HtmlDocument::AddTable(const Table& table) {
  std::string error;
  PNEUMID_CHECK(table.IsValid(&error), "{}", error);
  std::ostringstream os;
  os << "<table class=\"data\">";
  if (!table.caption.empty()) os << "<caption>" << HtmlEscape(table.caption) << "</caption>";
  os << "<thead><tr>";
  for (const auto& h : table.header) os << "<th>" << HtmlEscape(h) << "</th>";
  os << "</tr></thead><tbody>";
  for (const auto& row : table.rows) {
    os << "<tr>";
    for (const auto& c : row) os << "<td>" << HtmlEscape(c) << "</td>";
    os << "</tr>";
  }
  os << "</tbody></table>";
  blocks_.push_back(os.str());
  ++num_tables_;
}

void HtmlDocument::AddFigure(const Figure& figure, const std::string& caption) {
  const std::string svg = figure.ToSvg(fmt::format("f{}", num_figures_ + 1));
  blocks_.push_back("<figure class=\"plot\">" + svg + "<figcaption>" + HtmlEscape(caption) +
                    "</figcaption></figure>");
  ++num_figures_;
}

void HtmlDocument::AddCommands(const std::vector<std::string>& lines) {
  std::string s = "<pre class=\"commands\"><code>";
  for (const auto& l : lines) s += HtmlEscape(l) + "\n";
  blocks_.push_back(s + "</code></pre>");
}

std::string HtmlDocument::Render() const {
  std::ostringstream os;
  os << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
     << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
     << "<meta name=\"generator\" content=\"pneumid " << HtmlEscape(std::string(Version()))
     << "\">\n<title>" << HtmlEscape(title_) << "</title>\n<style>" << kStyle
     << "</style>\n</head>\n<body>\n<header><h1>" << HtmlEscape(title_) << "</h1><p>pneumid "
     << HtmlEscape(std::string(Version())) << "</p></header>\n<main>\n";
  for (const auto& b : blocks_) os << b << "\n";
  if (section_open_) os << "</section>\n";
  os << "</main>\n<footer>Generated by pneumid " << HtmlEscape(std::string(Version()))
     << "</footer>\n</body>\n</html>\n";
  return os.str();
}

void HtmlDocument::Write(const std::string& path) const {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw DataError(path + ": cannot open the file for writing");
  out << Render();
  out.close();
  if (!out) throw DataError(path + ": write failed");
}

}  // namespace pneumid
