#include "table.hpp"

#include <gtest/gtest.h>

namespace agnocast::cli {
namespace {

TEST(Table, AlignsColumnsTwoSpacesApartWithoutTrailingBlanks) {
  Table table({{"NAME"}, {"COUNT", Table::Align::right}, {"NOTE"}});
  table.add_row({"/chatter", "7", "x"});
  table.add_row({"/a", "1234567", ""});
  EXPECT_EQ(table.render(),
            "NAME        COUNT  NOTE\n"
            "/chatter        7  x\n"
            "/a        1234567\n");
}

TEST(Table, HeaderOnlyWhenEmpty) {
  Table table({{"A"}, {"B"}});
  EXPECT_EQ(table.render(), "A  B\n");
}

TEST(Table, RejectsRowOfWrongWidth) {
  Table table({{"A"}, {"B"}});
  EXPECT_THROW(table.add_row({"1"}), std::invalid_argument);
}

TEST(Cell, RendersEachJsonKind) {
  EXPECT_EQ(cell(nullptr), "-");
  EXPECT_EQ(cell(true), "yes");
  EXPECT_EQ(cell(false), "no");
  EXPECT_EQ(cell("/chatter"), "/chatter");
  EXPECT_EQ(cell(""), "-");
  EXPECT_EQ(cell(42), "42");
  EXPECT_EQ(cell(nlohmann::json::array({"/a", "/b"})), "/a,/b");
  EXPECT_EQ(cell(nlohmann::json::array()), "-");
}

TEST(KeyValueLines, AlignsValues) {
  const nlohmann::json value = {{"cli", "0.1.0"}, {"module", nullptr}};
  EXPECT_EQ(key_value_lines(value, {"cli", "module"}), "cli     0.1.0\nmodule  -\n");
}

}  // namespace
}  // namespace agnocast::cli
