// Sensor widths (long side, mm) of common cameras, from published sensor formats and
// pixel pitch x pixel count in manufacturers' spec sheets. They seed self-calibration,
// so a few percent of error is fine.
#include <cctype>
#include <string>

#include "core/io/sensor_table.h"

namespace reconar::io_internal {

namespace {

struct SensorEntry {
  const char* make;   // matched as a substring of the EXIF Make ("NIKON CORPORATION" has "nikon")
  const char* model;  // the EXIF Model without the make; a trailing '*' matches any suffix
  double width_mm;
};

constexpr SensorEntry kSensors[] = {
    // Apple: the main (wide) camera; other lenses usually come with a 35 mm equivalent anyway.
    {"apple", "iPhone 4", 4.54},
    {"apple", "iPhone 4S", 4.57},
    {"apple", "iPhone 5", 4.57},
    {"apple", "iPhone 5s", 4.89},
    {"apple", "iPhone 6", 4.89},
    {"apple", "iPhone 6 Plus", 4.89},
    {"apple", "iPhone 6s", 4.92},
    {"apple", "iPhone 6s Plus", 4.92},
    {"apple", "iPhone 7", 4.92},
    {"apple", "iPhone 7 Plus", 4.92},
    {"apple", "iPhone 8", 4.92},
    {"apple", "iPhone 8 Plus", 4.92},
    {"apple", "iPhone X", 4.92},
    {"apple", "iPhone XS", 5.64},
    {"apple", "iPhone XS Max", 5.64},
    {"apple", "iPhone XR", 5.64},
    {"apple", "iPhone 11", 5.64},
    {"apple", "iPhone 11 Pro", 5.64},
    {"apple", "iPhone 11 Pro Max", 5.64},
    {"apple", "iPhone 12", 5.64},
    {"apple", "iPhone 12 mini", 5.64},
    {"apple", "iPhone 12 Pro", 5.64},
    {"apple", "iPhone 12 Pro Max", 6.85},
    {"apple", "iPhone 13", 6.85},
    {"apple", "iPhone 13 mini", 6.85},
    {"apple", "iPhone 13 Pro", 7.66},
    {"apple", "iPhone 13 Pro Max", 7.66},
    {"apple", "iPhone 14", 7.66},
    {"apple", "iPhone 14 Plus", 7.66},
    {"apple", "iPhone 14 Pro", 9.84},
    {"apple", "iPhone 14 Pro Max", 9.84},
    {"apple", "iPhone 15", 8.06},
    {"apple", "iPhone 15 Plus", 8.06},
    {"apple", "iPhone 15 Pro", 9.84},
    {"apple", "iPhone 15 Pro Max", 9.84},
    // Google Pixel
    {"google", "Pixel", 6.25},
    {"google", "Pixel XL", 6.25},
    {"google", "Pixel 2", 5.64},
    {"google", "Pixel 2 XL", 5.64},
    {"google", "Pixel 3", 5.64},
    {"google", "Pixel 3 XL", 5.64},
    {"google", "Pixel 3a", 5.64},
    {"google", "Pixel 4", 5.64},
    {"google", "Pixel 4a", 5.64},
    {"google", "Pixel 5", 5.64},
    {"google", "Pixel 6a", 5.64},
    {"google", "Pixel 6", 9.79},
    {"google", "Pixel 6 Pro", 9.79},
    {"google", "Pixel 7", 9.79},
    {"google", "Pixel 7 Pro", 9.79},
    {"google", "Pixel 8", 9.79},
    {"google", "Pixel 8 Pro", 9.79},
    // Samsung Galaxy S (EXIF Model is the SM- code; the suffix is the regional variant)
    {"samsung", "SM-G930*", 5.64},  // S7
    {"samsung", "SM-G935*", 5.64},  // S7 edge
    {"samsung", "SM-G950*", 5.64},  // S8
    {"samsung", "SM-G955*", 5.64},  // S8+
    {"samsung", "SM-G960*", 5.64},  // S9
    {"samsung", "SM-G965*", 5.64},  // S9+
    {"samsung", "SM-G973*", 5.64},  // S10
    {"samsung", "SM-G975*", 5.64},  // S10+
    {"samsung", "SM-G98*", 7.20},   // S20, S20+
    {"samsung", "SM-G991*", 7.20},  // S21
    {"samsung", "SM-G996*", 7.20},  // S21+
    {"samsung", "SM-S901*", 8.16},  // S22
    {"samsung", "SM-S911*", 8.16},  // S23
    // Canon APS-C and full frame
    {"canon", "EOS 7D", 22.3},
    {"canon", "EOS 80D", 22.5},
    {"canon", "EOS 90D", 22.3},
    {"canon", "EOS 750D", 22.3},
    {"canon", "EOS REBEL T6i", 22.3},
    {"canon", "EOS 200D", 22.3},
    {"canon", "EOS REBEL SL2", 22.3},
    {"canon", "EOS 2000D", 22.3},
    {"canon", "EOS REBEL T7", 22.3},
    {"canon", "EOS M50", 22.3},
    {"canon", "EOS 5D Mark II", 36.0},
    {"canon", "EOS 5D Mark III", 36.0},
    {"canon", "EOS 5D Mark IV", 36.0},
    {"canon", "EOS 6D", 35.8},
    {"canon", "EOS R", 36.0},
    {"canon", "EOS R5", 36.0},
    {"canon", "EOS R6", 35.9},
    {"canon", "PowerShot A10", 5.27},
    // Nikon
    {"nikon", "D750", 35.9},
    {"nikon", "D810", 35.9},
    {"nikon", "D850", 35.9},
    {"nikon", "Z 6", 35.9},
    {"nikon", "Z 7", 35.9},
    {"nikon", "D7500", 23.5},
    {"nikon", "D5300", 23.5},
    {"nikon", "D3500", 23.5},
    // Sony
    {"sony", "ILCE-7M3", 35.6},
    {"sony", "ILCE-7RM3", 35.9},
    {"sony", "ILCE-7RM4", 35.7},
    {"sony", "ILCE-6000", 23.5},
    {"sony", "ILCE-6400", 23.5},
    {"sony", "DSC-RX100*", 13.2},
    // Action cameras, drones, others
    {"gopro", "HERO*", 6.17},
    {"dji", "FC6310*", 13.2},  // Phantom 4 Pro
    {"dji", "FC330", 6.17},    // Phantom 4
    {"dji", "FC220", 6.17},    // Mavic Pro
    {"dji", "L1D-20c", 13.2},  // Mavic 2 Pro
    {"dji", "FC3170", 6.40},   // Mavic Air 2
    {"dji", "FC7303", 6.17},   // Mini 2
    {"kodak", "Z612*", 5.76},
};

std::string Normalize(std::string_view text) {
  std::string s;
  for (char c : text) s += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const size_t first = s.find_first_not_of(' ');
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(' ') - first + 1);
}

bool ModelMatches(const std::string& model, const std::string& pattern) {
  if (!pattern.empty() && pattern.back() == '*') return model.compare(0, pattern.size() - 1, pattern, 0, pattern.size() - 1) == 0;
  return model == pattern;
}

}  // namespace

std::optional<double> LookupSensorWidthMm(std::string_view make, std::string_view model) {
  const std::string make_n = Normalize(make);
  const std::string model_n = Normalize(model);
  if (make_n.empty() || model_n.empty()) return std::nullopt;
  for (const SensorEntry& entry : kSensors) {
    const std::string key(entry.make);
    if (make_n.find(key) == std::string::npos) continue;
    std::string bare = model_n;
    if (bare.compare(0, key.size() + 1, key + " ") == 0) bare = Normalize(bare.substr(key.size() + 1));
    if (ModelMatches(bare, Normalize(entry.model))) return entry.width_mm;
  }
  return std::nullopt;
}

}  // namespace reconar::io_internal
