#pragma once
// io/formats/csv.hpp -- the one CSV reader of the library: a line into cells, numbers, text checks,
// and an output series.
//
// Cells are trimmed of blanks; a cell may be quoted ("a, b"; "" is a quote inside), as
// spreadsheets write them. '#' lines are comments. Text must be UTF-8 (a UTF-8 byte-order
// mark, as Excel's "CSV UTF-8" writes it, is dropped); numbers are finite decimals
// (parse_decimal: a decimal comma is refused, naming it); the separator is the header's: ','
// when it has one, else ';' or a tab (a spreadsheet's export in a comma-decimal locale).
#include <cstddef>
#include <array>
#include <functional>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vrelab::io {

// One CSV line into cells at `separator` (',', ';' or '\t'); blanks around a cell are trimmed
// (a tab only when it is not the separator). An unclosed quote, or text after a quoted cell,
// is FormatError at `path`:`line_no`.
std::vector<std::string> split_csv_line(const std::string& line, const std::string& path, long line_no, char separator = ',');

// A finite decimal number as a lab writes it: [+-]digits[.digits][(e|E)[+-]digits] (".5" and
// "5." too), nothing else: no blanks, no hexadecimal (strtod reads "0x1E" as 30), no inf or
// nan, no decimal comma, no value beyond the double range. nullopt for anything else.
std::optional<double> parse_decimal(std::string_view s);
// Why `s` is not a finite decimal, for a message: "hexadecimal", "not finite", "a decimal
// comma", or "not a number".
std::string why_not_decimal(std::string_view s);

// The byte offset of the first byte of `s` that does not belong to well-formed UTF-8
// (overlong forms, surrogates and code points past U+10FFFF included), or npos.
std::size_t first_non_utf8(std::string_view s);

// The checks every line of a text file passes before it is split: on line 1 a UTF-8
// byte-order mark is removed; a trailing '\r' is removed; a byte that is not UTF-8 is
// FormatError "<path>:<line>:<column>: not UTF-8 at byte N (0xB0) ...; save the file as UTF-8".
void check_text_line(std::string& line, long line_no, const std::string& path);

// The separator a file's header line uses: ',' when the line has one (outside or inside
// quotes: a comma file's header never needs ';'), else ';', else a tab, else ',' (one column).
// Every row of the file is split at it.
char header_separator(const std::string& header_line);
// The separator in words for messages: "','", "';'", "a tab".
std::string separator_name(char separator);

// A header naming a column twice (or an empty name twice) is FormatError at
// "<path>:<line>:<column>" naming the column: which of the two a reader took would be a guess.
void check_header_names(const std::vector<std::string>& header, const std::string& path, long line_no);

// The lab's own names for the columns and datasets of the files a run references (a
// manifest's [names] table: vrelab's name -> the lab's; docs/data-format.md, "The lab's own
// names"): a reader looks for the lab's name where it would look for vrelab's.
using ChannelNames = std::map<std::string, std::string>;
// The header with each lab's name that `names` maps put back to vrelab's name.
std::vector<std::string> with_vrelab_names(std::vector<std::string> header, const ChannelNames& names);

// The name in `names` closest to `name` (case-insensitive equality first, then edit
// distance at most 3), or "" when none is close.
std::string closest_name(const std::string& name, const std::vector<std::string>& names);

// A recorded output series: a header naming the columns, time (s) in the column time_s, else
// the first column. Streams (t, value of `column`) to `sample` row by row (`column` empty:
// the one column named output_<unit>, else the last column) and returns the column's name. Anything wrong (no file, no header, a
// column named twice, a field count, not a number, a sample outside its range (io/formats/ranges.hpp:
// time, output, reference), time not strictly increasing, `sample` rejecting a row with
// std::invalid_argument) is FormatError (io/formats/error.hpp) at the file and the line. read_series
// (io/formats/series.hpp) chooses this reader or the HDF5 one by the file's extension.
std::string read_series_csv(const std::string& path, const std::string& column,
                            const std::function<void(double t_s, double value)>& sample);
// Reference-accelerometer channels (the table's measured motion, g, sensor axes): columns
// ref_IA_g, ref_PA_g, ref_OA_g, or input_IA_g, input_PA_g, input_OA_g as `vrelab shake
// --series` writes the virtual table's motion (ref_ preferred), any of the three; `present`
// says which the header has. Called per row after `sample` when the header has any. A cell
// that is missing or not a finite decimal, or the sink throwing std::invalid_argument (e.g.
// rectification::ReferenceAnalyzer: another rate, another set of axes), is FormatError naming
// the file and the line ("f.csv:12:3: reference column ref_PA_g: 'nan' is not finite ...").
// Another reader (HDF5) calls the sink the same way, once per output sample.
using ReferenceSink = std::function<void(double t_s, const std::array<double, 3>& ref_g, const std::array<bool, 3>& present)>;
// The same from a stream (`path` only names it in messages): the in-memory entry point.
std::string read_series_csv(std::istream& in, const std::string& path, const std::string& column,
                            const std::function<void(double t_s, double value)>& sample,
                            const ReferenceSink& reference = {}, const ChannelNames& names = {});
std::string read_series_csv(const std::string& path, const std::string& column,
                            const std::function<void(double t_s, double value)>& sample, const ReferenceSink& reference,
                            const ChannelNames& names = {});

}  // namespace vrelab::io
