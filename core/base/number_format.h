#pragma once
// The one shortest-round-trip number formatter: the fewest digits that read back (std::from_chars,
// strtod) as the same value, as std::to_chars writes them ("0.1", "-0", "1e-300", "3", "inf", "nan").
// Every text file format (COLMAP models, mesh text formats, calibration, JSON) writes numbers
// through it. A float keeps float precision: 0.1f is "0.1", not "0.10000000149011612".
#include <string>

namespace reconar {

void AppendShortest(std::string* out, double value);
void AppendShortest(std::string* out, float value);
std::string FormatShortest(double value);
std::string FormatShortest(float value);

}  // namespace reconar
