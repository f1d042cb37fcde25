#include "io/formats/report.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
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

std::string Report::html() const {
  std::string o = fmt::format("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n", escape(title_));
  o += "<style>\n"
                  "body{font-family:system-ui,sans-serif;max-width:70em;margin:2em auto;padding:0 1em;line-height:1.45;color:#222}\n"
                  "table{border-collapse:collapse;margin:1em 0;font-size:0.9em}\n"
                  "th,td{border:1px solid #bbb;padding:0.25em 0.6em;text-align:right}\n"
                  "th{background:#eee}td:first-child,th:first-child{text-align:left}\n"
                  "figure{margin:1.5em 0}figure img{max-width:100%;border:1px solid #ddd}\n"
                  "figcaption{font-size:0.9em;color:#444}\n"
       "</style>\n</head>\n<body>\n";
  o += fmt::format("<h1>{}</h1>\n", escape(title_));
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Block::kHeading: o += fmt::format("<h2>{}</h2>\n", escape(b.text)); break;
      case Block::kParagraph: o += fmt::format("<p>{}</p>\n", escape(b.text)); break;
      case Block::kList:
        o += "<ul>\n";
        for (const auto& item : b.rows[0]) o += fmt::format("<li>{}</li>\n", escape(item));
        o += "</ul>\n";
        break;
      case Block::kTable:
        o += "<table>\n";
        for (std::size_t r = 0; r < b.rows.size(); ++r) {
          o += "<tr>";
          for (const auto& c : b.rows[r]) o += fmt::format("<{0}>{1}</{0}>", r == 0 ? "th" : "td", escape(c));
          o += "</tr>\n";
        }
        o += "</table>\n";
        break;
      case Block::kFigure:
        if (b.present)
          o += fmt::format("<figure><a href=\"{0}.svg\"><img src=\"{0}.png\" alt=\"{1}\"></a><figcaption>{1} (click for "
                           "SVG)</figcaption></figure>\n",
                           escape(b.stem), escape(b.text));
        else
          o += fmt::format("<p><em>Figure {} not drawn: {}.</em> {}</p>\n", escape(b.stem), escape(b.note), escape(b.text));
        break;
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
  write_atomic((dir / "report.html").string(), rep.html());
}

}  // namespace vrelab::io
