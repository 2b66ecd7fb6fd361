// The project's one CSV reader (caliper/csv.hpp, on libcsv): quoting, line ends, the byte order
// mark, comments, per-row errors, the messages' file/line/column, and the limits.
#include <string>

#include <gtest/gtest.h>

#include "caliper/csv.hpp"

namespace caliper {
namespace {

std::string message_of(const std::string& text, const CsvOptions& options = {}) {
  try {
    parse_csv(text, "t.csv", options);
  } catch (const CsvError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Csv, QuotesLineEndsAndByteOrderMark) {
  const CsvTable t =
      parse_csv("\xEF\xBB\xBFid,\"na,me\"\r\n1,\"a \"\"b\"\"\"\r\n\r\n2,c\r\n", "x.csv");
  ASSERT_EQ(t.header.size(), 2u);
  EXPECT_EQ(t.header[0], "id") << "the byte order mark is not part of the first cell";
  EXPECT_EQ(t.header[1], "na,me");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0][1], "a \"b\"");
  EXPECT_EQ(t.line_numbers[0], 2);
  EXPECT_EQ(t.line_numbers[1], 4) << "the blank line 3 is skipped but counted";
  EXPECT_EQ(t.column("NA,ME"), 1);
  EXPECT_EQ(t.column("missing"), -1);
  // Bytes are kept: Latin-1, and the spaces of unquoted cells (header cells are trimmed).
  const CsvTable l = parse_csv(" a ,b\nM\xE9tis , x\n", "l.csv");
  EXPECT_EQ(l.header[0], "a");
  EXPECT_EQ(l.rows[0][0], "M\xE9tis ");
  EXPECT_EQ(l.rows[0][1], " x");
  // The last line needs no line break; a quoted cell may span lines (its row's first line counts).
  const CsvTable m = parse_csv("a,b\n\"x\ny\",1\n3,4", "m.csv");
  ASSERT_EQ(m.rows.size(), 2u);
  EXPECT_EQ(m.rows[0][0], "x\ny");
  EXPECT_EQ(m.line_numbers[1], 4);
  EXPECT_EQ(m.rows[1][1], "4");
}

TEST(Csv, ErrorsNameFileLineAndColumn) {
  EXPECT_NE(message_of("a,b\n1,2\n3\n").find("t.csv:3: 1 cells, but the header has 2"),
            std::string::npos);
  EXPECT_NE(message_of("a,b\n1,x\"y\n").find("t.csv:2:4: a quote inside an unquoted cell"),
            std::string::npos)
      << message_of("a,b\n1,x\"y\n");
  EXPECT_NE(message_of("a,b\n\"1\"z,2\n").find("t.csv:2:4:"), std::string::npos);
  EXPECT_NE(message_of("a,b\n1,2\n\"x,1\n").find("t.csv:3: unclosed quote"), std::string::npos);
  EXPECT_NE(message_of("").find("t.csv: empty CSV file"), std::string::npos);
  EXPECT_NE(message_of("\n\r\n").find("empty CSV file"), std::string::npos);
  try {
    read_csv("/nonexistent/people.csv");
    FAIL();
  } catch (const CsvError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/people.csv: cannot open"),
              std::string::npos);
  }
}

TEST(Csv, CommentLines) {
  const std::string text = "# note\nh1,h2\n# another\n1,\"#2\"\n";
  const CsvTable t = parse_csv(text, "c.csv", CsvOptions{false, /*comment_lines=*/true});
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_EQ(t.header[0], "h1");
  EXPECT_EQ(t.rows[0][1], "#2");
  EXPECT_EQ(t.line_numbers[0], 4);
  EXPECT_NE(message_of(text).find("t.csv:2: 2 cells, but the header has 1"), std::string::npos)
      << "without the option '#' lines are rows";
}

TEST(Csv, PerRowErrorsKeepTheOtherRows) {
  const CsvOptions per_row{/*per_row_errors=*/true};
  const CsvTable t = parse_csv("id,h\na,1\nb,\"2\nc\"x\"y,3\nd,4,5\ne,5\nf,\"6", "p.csv", per_row);
  ASSERT_EQ(t.rows.size(), 6u);
  const std::vector<std::string> ids = {"a", "b", "cxy", "d", "e", "f"};
  for (size_t i = 0; i < ids.size(); ++i) {
    EXPECT_EQ(t.rows[i][0], ids[i]);
    EXPECT_EQ(t.rows[i].size(), 2u) << "padded or cut to the header";
    EXPECT_EQ(t.line_numbers[i], static_cast<int>(i) + 2);
  }
  EXPECT_EQ(t.row_errors[0], "");
  EXPECT_EQ(t.row_errors[1],
            "p.csv:3: a quoted cell is not closed on this line; check for a stray \"");
  EXPECT_NE(t.row_errors[2].find("p.csv:4:2: a quote inside an unquoted cell"), std::string::npos)
      << t.row_errors[2];
  EXPECT_EQ(t.row_errors[3], "p.csv:5: 3 cells, but the header has 2; check for a missing comma");
  EXPECT_EQ(t.row_errors[4], "");
  EXPECT_NE(t.row_errors[5].find("p.csv:7: a quoted cell is not closed"), std::string::npos);
  // The header row itself must be well formed.
  EXPECT_NE(message_of("id,\"h\n", per_row).find("unclosed quote"), std::string::npos);
}

TEST(Csv, LimitsAgainstHostileFiles) {
  const std::string long_cell(kCsvMaxRowBytes + 1, 'x');
  EXPECT_NE(message_of("a\n" + long_cell + "\n").find("t.csv:2: a row longer than 1 MiB"),
            std::string::npos);
  // A quote never closed cannot make the reader hold more than one row's limit either.
  std::string open_quote = "a\n\"";
  for (size_t i = 0; i * 64 < kCsvMaxRowBytes; ++i) open_quote += std::string(63, 'y') + "\n";
  EXPECT_NE(message_of(open_quote).find("t.csv:2: a row longer than"), std::string::npos);
  const std::string many_cells(kCsvMaxCells, ',');
  EXPECT_NE(message_of("a\n" + many_cells + "\n").find("t.csv:2: more than 10000 cells"),
            std::string::npos);
  // Just under both limits is a (malformed-width) row, not a limit error.
  const std::string wide(kCsvMaxCells - 1, ',');
  EXPECT_NE(message_of("a\n" + wide + "\n").find("10000 cells, but the header has 1"),
            std::string::npos);
}

TEST(Csv, EscapeIsTheInverseOfTheReader) {
  EXPECT_EQ(csv_escape("plain"), "plain");
  EXPECT_EQ(csv_escape("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_escape("say \"hi\"\nbye"), "\"say \"\"hi\"\"\nbye\"");
  const std::string cells[] = {"a,b", "q\"q", "line\r\nbreak", "", "M\xE9tis"};
  std::string text = "c0,c1,c2,c3,c4\n";
  for (size_t i = 0; i < 5; ++i) text += (i ? "," : "") + csv_escape(cells[i]);
  const CsvTable t = parse_csv(text + "\n", "e.csv");
  ASSERT_EQ(t.rows.size(), 1u);
  for (size_t i = 0; i < 5; ++i) EXPECT_EQ(t.rows[0][i], cells[i]);
}

}  // namespace
}  // namespace caliper
