#pragma once
// The order in which image files are taken from a folder: the order a person reads numbered
// files in. Runs of digits compare by their value, so frame_9.png comes before frame_10.png (a
// plain string sort puts frame_10 through frame_19 between frame_1 and frame_2, and a video read
// in that order jumps back and forth). Everything else compares byte by byte; names equal in value
// ("frame_01", "frame_1") fall back to the byte order, so the order is total.
#include <string>
#include <vector>

namespace reconar {

bool FileNameLess(const std::string& a, const std::string& b);
void SortFileNames(std::vector<std::string>* names);

}  // namespace reconar
