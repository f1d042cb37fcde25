// The CSV text checks every reader makes (io/formats/csv.hpp): finite decimal numbers only,
// UTF-8 byte by byte, the closest column name suggested, the header's separator.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "io/formats/csv.hpp"
#include "io/formats/error.hpp"

namespace test_csv_text {

using namespace vrelab;

// Numbers as a lab writes them: finite decimals only. strtod alone reads "0x1E" as 30, "inf"
// and "nan" as themselves, and stops quietly at a decimal comma.
TEST(CsvText, OnlyFiniteDecimalNumbersAreNumbers) {
  EXPECT_EQ(io::parse_decimal("30").value(), 30.0);
  EXPECT_EQ(io::parse_decimal("-1.5e-3").value(), -1.5e-3);
  EXPECT_EQ(io::parse_decimal(".5").value(), 0.5);
  EXPECT_EQ(io::parse_decimal("5.").value(), 5.0);
  EXPECT_EQ(io::parse_decimal("+2E+2").value(), 200.0);
  for (const char* bad : {"0x1E", "0X1e", "inf", "-inf", "nan", "NaN", "1,5", " 1", "1 ", "", "-", ".", "e5", "1e", "1e+",
                          "1.2.3", "1e999", "12abc"})
    EXPECT_FALSE(io::parse_decimal(bad).has_value()) << bad;
  EXPECT_EQ(io::why_not_decimal("0x1E"), "hexadecimal; write the decimal value");
  EXPECT_EQ(io::why_not_decimal("nan"), "not finite");
  EXPECT_EQ(io::why_not_decimal("1,5"), "a decimal comma; write a decimal point");
}

// UTF-8 as RFC 3629 has it: a Latin-1 degree sign (0xB0) is not UTF-8, its UTF-8 form (C2 B0)
// is; overlong forms, surrogates and truncated sequences are not.
TEST(CsvText, Utf8IsCheckedByteByByte) {
  EXPECT_EQ(io::first_non_utf8("angle 30\xC2\xB0"), std::string::npos);
  EXPECT_EQ(io::first_non_utf8("\xE2\x82\xAC \xF0\x9F\x98\x80"), std::string::npos);  // euro, an emoji
  EXPECT_EQ(io::first_non_utf8("id\xB0"), 2u);
  EXPECT_EQ(io::first_non_utf8("\xC0\xAF"), 0u);          // overlong '/'
  EXPECT_EQ(io::first_non_utf8("a\xED\xA0\x80"), 1u);     // a surrogate
  EXPECT_EQ(io::first_non_utf8("ab\xE2\x82"), 2u);        // truncated at the end
  EXPECT_EQ(io::first_non_utf8("\xF4\x90\x80\x80"), 0u);  // past U+10FFFF
  std::string bom = "\xEF\xBB\xBFid,frequency_Hz\r";
  io::check_text_line(bom, 1, "runs.csv");
  EXPECT_EQ(bom, "id,frequency_Hz");
  std::string latin1 = "run\xB0,1";
  try {
    io::check_text_line(latin1, 7, "runs.csv");
    ADD_FAILURE() << "accepted a Latin-1 byte";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("runs.csv:7:4: not UTF-8 at byte 4 (0xB0"), std::string::npos) << e.what();
  }
}

TEST(CsvText, ClosestColumnNameIsSuggested) {
  const std::vector<std::string> names = {"id", "frequency_Hz", "amplitude_g"};
  EXPECT_EQ(io::closest_name("frequency_hz", names), "frequency_Hz");
  EXPECT_EQ(io::closest_name("amplitud_g", names), "amplitude_g");
  EXPECT_EQ(io::closest_name("temperature_C", names), "");
}

// A spreadsheet's export in a comma-decimal locale separates by ';' (or a tab): the header
// says which, every row is split at it. Cells are trimmed of blanks but a tab separator is not
// a blank (an empty cell between two tabs stays a cell); a quoted cell may hold the separator.
TEST(CsvText, TheHeadersSeparatorSplitsEveryRow) {
  EXPECT_EQ(io::header_separator("id,frequency_Hz"), ',');
  EXPECT_EQ(io::header_separator("id;frequency_Hz"), ';');
  EXPECT_EQ(io::header_separator("id\tfrequency_Hz"), '\t');
  EXPECT_EQ(io::header_separator("\"a;b\",c"), ',');  // a comma anywhere: a comma file
  EXPECT_EQ(io::header_separator("time_s"), ',');
  using Cells = std::vector<std::string>;
  EXPECT_EQ(io::split_csv_line(" a ; 1.5;;\"x;y\" ", "f.csv", 2, ';'), (Cells{"a", "1.5", "", "x;y"}));
  EXPECT_EQ(io::split_csv_line("a\t\t 2 \t", "f.csv", 2, '\t'), (Cells{"a", "", "2", ""}));
  EXPECT_EQ(io::split_csv_line("0,88;1", "f.csv", 2, ';'), (Cells{"0,88", "1"}));  // a decimal comma is a cell's text
  EXPECT_EQ(io::split_csv_line("a, b", "f.csv", 2), (Cells{"a", "b"}));
  EXPECT_EQ(io::separator_name('\t'), "a tab");
  EXPECT_EQ(io::separator_name(';'), "';'");
  // A series in ';' reads as its comma twin, sample for sample; with decimal commas it is
  // refused at the line, naming the decimal comma.
  const auto read = [](const std::string& text) {
    std::istringstream in(text);
    std::vector<std::pair<double, double>> s;
    io::read_series_csv(in, "rec.csv", "", [&](double t, double u) { s.emplace_back(t, u); });
    return s;
  };
  const auto comma = read("time_s,output_mA\n0,0.88\n0.001,0.89\n");
  ASSERT_EQ(comma.size(), 2u);
  EXPECT_EQ(read("time_s;output_mA\n0;0.88\n0.001;0.89\n"), comma);
  EXPECT_EQ(read("time_s\toutput_mA\n0\t0.88\n0.001\t0.89\n"), comma);
  try {
    read("time_s;output_mA\n0;0,88\n");
    ADD_FAILURE() << "read a decimal comma";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rec.csv:2: not a number in '0;0,88' (column 2, '0,88': a decimal comma; write a decimal point)"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace test_csv_text
