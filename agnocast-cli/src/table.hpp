// Aligned plain-text tables: the human rendering of every command's JSON value.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace agnocast::cli {

class Table {
 public:
  enum class Align { left, right };
  struct Column {
    std::string header;
    Align align = Align::left;
  };

  explicit Table(std::vector<Column> columns);
  // Throws std::invalid_argument when the row does not have one cell per column.
  void add_row(std::vector<std::string> cells);
  // Header then rows, columns two spaces apart, no trailing blanks, '\n' after each line.
  std::string render() const;

 private:
  std::vector<Column> columns_;
  std::vector<std::vector<std::string>> rows_;
};

// One JSON value as a table cell: null "-", booleans "yes"/"no", strings
// unquoted (empty "-"), arrays comma-separated (empty "-"), numbers as JSON writes them.
std::string cell(const nlohmann::json& value);

// "key  value" lines for one flat object, in the given key order.
std::string key_value_lines(const nlohmann::json& object, const std::vector<std::string>& keys);

// A number of seconds as a message shows it: 2, 0.5, 1e-05.
std::string seconds_text(double seconds);

}  // namespace agnocast::cli
