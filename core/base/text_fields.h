#pragma once
// The whitespace-separated fields of a line of a text format (COLMAP and Bundler models, PLY,
// OBJ, VRML): views into the line, no copies.
#include <string_view>
#include <vector>

namespace reconar {

// The fields of `line` separated by spaces, tabs or carriage returns, into *fields (cleared first,
// so that a reader can reuse it line after line).
inline void SplitFields(std::string_view line, std::vector<std::string_view>* fields) {
  fields->clear();
  size_t i = 0;
  while (i < line.size()) {
    const size_t begin = line.find_first_not_of(" \t\r", i);
    if (begin == std::string_view::npos) break;
    size_t end = line.find_first_of(" \t\r", begin);
    if (end == std::string_view::npos) end = line.size();
    fields->push_back(line.substr(begin, end - begin));
    i = end;
  }
}

inline std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  SplitFields(line, &fields);
  return fields;
}

}  // namespace reconar
