#pragma once
// io/formats/report.hpp -- a report written once, rendered as Markdown and as HTML.
//
// Takes: a summary (the verdict or headline and a few lines: always shown first, in a box),
//        then headings, paragraphs, tables (first row: the header), figures (a file stem in the
//        report's folder, stem.png/stem.svg as the plot scripts write them) and bullet lists, in
//        order.
// Gives: the same document as Markdown (figures linked) and as one HTML page that stands alone
//        (one style for every command's report; no scripts, no external resources: each figure
//        is read from the folder and embedded as a data URI, so the page can be mailed). Text
//        is plain: HTML special characters are escaped, nothing is interpreted as markup.
#include <string>
#include <vector>

namespace vrelab::io {

class Report {
 public:
  // The summary box's colour: good (a clear result), bad (a problem to act on), plain.
  enum class Tone { plain, good, bad };

  explicit Report(std::string title) : title_(std::move(title)) {}
  void summary(const std::string& headline, const std::vector<std::string>& lines, Tone tone = Tone::plain);
  void heading(const std::string& text);  // a section (level 2)
  void paragraph(const std::string& text);
  void list(const std::vector<std::string>& items);
  void table(const std::vector<std::vector<std::string>>& rows);
  // A figure `stem` (.png/.svg) with its caption; `present` false: the caption says the
  // figure was not drawn and why (`missing_reason`).
  void figure(const std::string& stem, const std::string& caption, bool present, const std::string& missing_reason);

  std::string markdown() const;
  // `dir`: the folder holding the figures, each embedded (its SVG, or its PNG when the SVG is
  // missing or larger); a figure whose files are missing is said so.
  std::string html(const std::string& dir) const;

 private:
  struct Block {
    enum Kind { kHeading, kParagraph, kList, kTable, kFigure } kind;
    std::string text;
    std::vector<std::vector<std::string>> rows;  // table rows; list items in rows[0]
    std::string stem, note;
    bool present = true;
  };
  std::string title_;
  std::string headline_;
  std::vector<std::string> summary_lines_;
  Tone tone_ = Tone::plain;
  std::vector<Block> blocks_;
};

// ---- A report folder (reproduce --out, diagnose --report): a new run's files never sit beside
// an old report, and a report is only there when everything it shows is.
//
// The folder is kept, not swapped: it may hold the user's own files (or be the campaign's
// own folder), which writing the report into a sibling folder and renaming it over would
// take away. Instead DIR/report-files.txt lists what the last report wrote:
// begin_report_folder removes report.html and report.md first, then every file the list names
// (figures included, so a run drawing fewer figures leaves none of the old ones) and, when the
// last run was killed before its list was complete, every file written since it began; it
// then starts a new list. write_report_folder lists every file written since (data, figures)
// and writes report.md and, last, report.html. Files are each written atomically
// (write_atomic; the plot scripts through tools/plots/atomic_figure.py), so a killed run
// leaves whole files of the new run and no report.
void begin_report_folder(const std::string& dir);
void write_report_folder(const std::string& dir, const Report& rep);

}  // namespace vrelab::io
