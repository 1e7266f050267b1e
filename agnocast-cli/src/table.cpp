#include "table.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace agnocast::cli {

Table::Table(std::vector<Column> columns) : columns_(std::move(columns)) {}

void Table::add_row(std::vector<std::string> cells) {
  if (cells.size() != columns_.size()) {
    throw std::invalid_argument("table row has " + std::to_string(cells.size()) + " cells for " +
                                std::to_string(columns_.size()) + " columns");
  }
  rows_.push_back(std::move(cells));
}

std::string Table::render() const {
  std::vector<std::size_t> widths;
  for (const Column& column : columns_) widths.push_back(column.header.size());
  for (const auto& row : rows_) {
    for (std::size_t i = 0; i < row.size(); ++i) widths[i] = std::max(widths[i], row[i].size());
  }
  std::string text;
  auto add_line = [&](const std::vector<std::string>& cells) {
    std::string line;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string padding(widths[i] - cells[i].size(), ' ');
      if (i > 0) line += "  ";
      line += columns_[i].align == Align::right ? padding + cells[i] : cells[i] + padding;
    }
    line.erase(line.find_last_not_of(' ') + 1);
    text += line + '\n';
  };
  std::vector<std::string> headers;
  for (const Column& column : columns_) headers.push_back(column.header);
  add_line(headers);
  for (const auto& row : rows_) add_line(row);
  return text;
}

std::string cell(const nlohmann::json& value) {
  if (value.is_null()) return "-";
  if (value.is_boolean()) return value.get<bool>() ? "yes" : "no";
  if (value.is_string()) return value.get<std::string>().empty() ? "-" : value.get<std::string>();
  if (value.is_array()) {
    if (value.empty()) return "-";
    std::string joined;
    for (const auto& item : value) {
      if (!joined.empty()) joined += ',';
      joined += cell(item);
    }
    return joined;
  }
  return value.dump();
}

std::string key_value_lines(const nlohmann::json& object, const std::vector<std::string>& keys) {
  std::size_t width = 0;
  for (const std::string& key : keys) width = std::max(width, key.size());
  std::string text;
  for (const std::string& key : keys) {
    const std::string value = object.contains(key) ? cell(object.at(key)) : "-";
    text += key + std::string(width - key.size() + 2, ' ') + value + '\n';
  }
  return text;
}

std::string seconds_text(double seconds) {
  std::ostringstream text;
  text << seconds;
  return text.str();
}

}  // namespace agnocast::cli
