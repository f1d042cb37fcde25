#include "io/formats/report.hpp"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include <fmt/format.h>

#include "io/formats/output.hpp"

namespace vrelab::io {
namespace {

std::string escape(const std::string& s) {
  std::string o;
  for (char ch : s) {
    switch (ch) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += ch;
    }
  }
  return o;
}

std::string md_cell(const std::string& s) {
  std::string o;
  for (char ch : s) o += ch == '|' ? std::string("\\|") : std::string(1, ch);
  return o;
}

}  // namespace

void Report::heading(const std::string& text) { blocks_.push_back({Block::kHeading, text, {}, "", "", true}); }
void Report::paragraph(const std::string& text) { blocks_.push_back({Block::kParagraph, text, {}, "", "", true}); }
void Report::list(const std::vector<std::string>& items) { blocks_.push_back({Block::kList, "", {items}, "", "", true}); }
void Report::table(const std::vector<std::vector<std::string>>& rows) {
  blocks_.push_back({Block::kTable, "", rows, "", "", true});
}
void Report::figure(const std::string& stem, const std::string& caption, bool present, const std::string& missing_reason) {
  blocks_.push_back({Block::kFigure, caption, {}, stem, missing_reason, present});
}

std::string Report::markdown() const {
  std::string o = fmt::format("# {}\n\n", title_);
  if (!headline_.empty()) {
    o += fmt::format("> **{}**\n", headline_);
    if (!summary_lines_.empty()) o += ">\n";
    for (const auto& l : summary_lines_) o += fmt::format("> - {}\n", l);
    o += "\n";
  }
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Block::kHeading: o += fmt::format("## {}\n\n", b.text); break;
      case Block::kParagraph: o += fmt::format("{}\n\n", b.text); break;
      case Block::kList:
        for (const auto& item : b.rows[0]) o += fmt::format("- {}\n", item);
        o += "\n";
        break;
      case Block::kTable:
        for (std::size_t r = 0; r < b.rows.size(); ++r) {
          o += "|";
          for (const auto& c : b.rows[r]) o += fmt::format(" {} |", md_cell(c));
          o += "\n";
          if (r == 0) {
            o += "|";
            for (std::size_t c = 0; c < b.rows[0].size(); ++c) o += " --- |";
            o += "\n";
          }
        }
        o += "\n";
        break;
      case Block::kFigure:
        if (b.present)
          o += fmt::format("![{0}]({1}.png)\n\n*{0}* ([SVG]({1}.svg))\n\n", b.text, b.stem);
        else
          o += fmt::format("*Figure {} not drawn: {}.* {}\n\n", b.stem, b.note, b.text);
        break;
    }
  }
  return o;
}

namespace {

// The look every report shares: the summary box first, tables with their numbers right-aligned,
// figures as wide as the page.
constexpr const char* kStyle =
    "body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;max-width:72em;margin:1.5em auto;padding:0 1em;"
    "line-height:1.45;color:#1d1d1f}\n"
    "h1{font-size:1.5em;margin:0 0 .6em}h2{font-size:1.2em;margin:1.8em 0 .5em;padding-bottom:.2em;"
    "border-bottom:1px solid #ccc}\n"
    ".summary{border:1px solid #bbb;border-left:8px solid #888;background:#f6f6f6;padding:.6em 1.2em;margin:0 0 1.5em}\n"
    ".summary.good{border-left-color:#2e7d32;background:#eef7ee}.summary.bad{border-left-color:#c62828;background:#fbeeee}\n"
    ".summary .headline{font-size:1.3em;font-weight:600;margin:.3em 0}.summary ul{margin:.3em 0 .5em;padding-left:1.2em}\n"
    "table{border-collapse:collapse;margin:1em 0;font-size:.9em}\n"
    "th,td{border:1px solid #bbb;padding:.25em .6em;text-align:left;vertical-align:top}\n"
    "th{background:#eee}.n{text-align:right}tr:nth-child(even) td{background:#fafafa}\n"
    "figure{margin:1.5em 0}figure img{width:100%;border:1px solid #ddd}\n"
    "figcaption{font-size:.9em;color:#444}\n";

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string base64(const std::string& bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  o.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t j = 0; j < 3; ++j) v = v << 8 | (j < n ? static_cast<unsigned char>(bytes[i + j]) : 0u);
    for (std::size_t j = 0; j < 4; ++j) o += j <= n ? kDigits[(v >> (18 - 6 * j)) & 63] : '=';
  }
  return o;
}

// Columns right-aligned: those whose cells below the header each start with a number (or are
// empty, "n/a" or "(given)"), and not all empty.
std::vector<bool> numeric_columns(const std::vector<std::vector<std::string>>& rows) {
  const auto number = [](const std::string& c) {
    const auto digit = [](char ch) { return ch >= '0' && ch <= '9'; };
    return digit(c[0]) || (c.size() > 1 && (c[0] == '-' || c[0] == '+' || c[0] == '.') && digit(c[1]));
  };
  std::vector<bool> numeric(rows.empty() ? 0 : rows[0].size(), true), seen(numeric.size(), false);
  for (std::size_t r = 1; r < rows.size(); ++r)
    for (std::size_t c = 0; c < rows[r].size() && c < numeric.size(); ++c) {
      const std::string& x = rows[r][c];
      if (x.empty() || x == "n/a" || x == "(given)") continue;
      seen[c] = true;
      numeric[c] = numeric[c] && number(x);
    }
  for (std::size_t c = 0; c < numeric.size(); ++c) numeric[c] = numeric[c] && seen[c];
  return numeric;
}

// The figure `stem` in `dir` as a data URI: the SVG (sharp at any zoom), or the PNG when the SVG
// is missing or larger; "" when neither file is there.
std::string figure_uri(const std::string& dir, const std::string& stem) {
  namespace fs = std::filesystem;
  const fs::path svg = fs::path(dir) / (stem + ".svg"), png = fs::path(dir) / (stem + ".png");
  std::error_code ec;
  const bool has_svg = fs::is_regular_file(svg, ec), has_png = fs::is_regular_file(png, ec);
  if (has_svg && (!has_png || fs::file_size(svg, ec) <= fs::file_size(png, ec)))
    return "data:image/svg+xml;base64," + base64(read_file(svg));
  if (has_png) return "data:image/png;base64," + base64(read_file(png));
  return "";
}

}  // namespace

void Report::summary(const std::string& headline, const std::vector<std::string>& lines, Tone tone) {
  headline_ = headline, summary_lines_ = lines, tone_ = tone;
}

std::string Report::html(const std::string& dir) const {
  std::string o = fmt::format("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n", escape(title_));
  o += fmt::format("<style>\n{}</style>\n</head>\n<body>\n<h1>{}</h1>\n", kStyle, escape(title_));
  if (!headline_.empty()) {
    o += fmt::format("<section class=\"summary{}\">\n<p class=\"headline\">{}</p>\n",
                     tone_ == Tone::good ? " good" : tone_ == Tone::bad ? " bad" : "", escape(headline_));
    if (!summary_lines_.empty()) {
      o += "<ul>\n";
      for (const auto& l : summary_lines_) o += fmt::format("<li>{}</li>\n", escape(l));
      o += "</ul>\n";
    }
    o += "</section>\n";
  }
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Block::kHeading: o += fmt::format("<h2>{}</h2>\n", escape(b.text)); break;
      case Block::kParagraph: o += fmt::format("<p>{}</p>\n", escape(b.text)); break;
      case Block::kList:
        o += "<ul>\n";
        for (const auto& item : b.rows[0]) o += fmt::format("<li>{}</li>\n", escape(item));
        o += "</ul>\n";
        break;
      case Block::kTable: {
        const std::vector<bool> numbers = numeric_columns(b.rows);
        o += "<table>\n";
        for (std::size_t r = 0; r < b.rows.size(); ++r) {
          o += "<tr>";
          for (std::size_t c = 0; c < b.rows[r].size(); ++c)
            o += fmt::format("<{0}{1}>{2}</{0}>", r == 0 ? "th" : "td", c < numbers.size() && numbers[c] ? " class=\"n\"" : "",
                             escape(b.rows[r][c]));
          o += "</tr>\n";
        }
        o += "</table>\n";
        break;
      }
      case Block::kFigure: {
        const std::string uri = b.present ? figure_uri(dir, b.stem) : "";
        if (!uri.empty())
          o += fmt::format("<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n", uri, escape(b.text),
                           escape(b.text));
        else
          o += fmt::format("<p><em>Figure {} not drawn: {}.</em> {}</p>\n", escape(b.stem),
                           escape(b.present ? "its file is missing" : b.note), escape(b.text));
        break;
      }
    }
  }
  o += "</body>\n</html>\n";
  return o;
}

namespace {

namespace fs = std::filesystem;
constexpr const char* kReportList = "report-files.txt";
constexpr const char* kComplete = "# complete";

// A name the list may hold: a plain file name in the folder (nothing outside it is removed).
bool plain_name(const std::string& n) {
  return !n.empty() && n[0] != '#' && n.find('/') == std::string::npos && n != "." && n != ".." && n != kReportList;
}

// Regular files of `dir` written at or after `since` (the list's own time), but the list and
// temporary files.
std::vector<std::string> written_since(const fs::path& dir, fs::file_time_type since) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (!e.is_regular_file(ec) || !plain_name(n) || n.find(".tmp.") != std::string::npos) continue;
    if (e.last_write_time(ec) >= since && !ec) out.push_back(n);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

void begin_report_folder(const std::string& dir_name) {
  const fs::path dir(dir_name), list = dir / kReportList;
  std::error_code ec;
  for (const char* f : {"report.html", "report.md"}) fs::remove(dir / f, ec);
  if (fs::is_regular_file(list, ec)) {
    std::ifstream in(list);
    bool complete = false;
    for (std::string line; std::getline(in, line);) {
      complete = complete || line == kComplete;
      if (plain_name(line)) fs::remove(dir / line, ec);
    }
    if (!complete) {  // the last run was killed: what it wrote is not listed
      const auto since = fs::last_write_time(list, ec);
      if (!ec)
        for (const auto& n : written_since(dir, since)) fs::remove(dir / n, ec);
    }
  }
  // The new list's time (the file system's clock, as the files' times are) marks the start.
  write_atomic(list.string(), "# vrelab report files (io/formats/report.hpp): removed before the next report is written here\n");
}

void write_report_folder(const std::string& dir_name, const Report& rep) {
  const fs::path dir(dir_name), list = dir / kReportList;
  std::error_code ec;
  const auto since = fs::last_write_time(list, ec);
  std::set<std::string> files = {"report.md", "report.html"};
  if (!ec)
    for (const auto& n : written_since(dir, since)) files.insert(n);
  std::string text = "# vrelab report files (io/formats/report.hpp): removed before the next report is written here\n";
  for (const auto& n : files) text += n + "\n";
  write_atomic(list.string(), text + kComplete + "\n");
  write_atomic((dir / "report.md").string(), rep.markdown());
  write_atomic((dir / "report.html").string(), rep.html(dir_name));
}

}  // namespace vrelab::io
