// Splitting a line of a CSV file that the tools write (the bench table, the documentation's
// measurement files): the tests read them back field by field.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace statsim::testing {

/// The fields of one CSV line: double quotes protect commas, "" is a quote, a carriage return is
/// dropped.
inline std::vector<std::string> csv_fields(const std::string& line)
{
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

}  // namespace statsim::testing
