#pragma once
// Test support for the map file (localization_map_io_test.cc, localization_map_fuzz.cc): a small
// localisation map of seeded random content, and the header repair that lets a mutated payload
// reach the structural parser behind the checksum.
#include <string>

#include "core/sfm/localization_map.h"

namespace reconar::testing {

// `num_points` random points (colour, descriptor) seen by `num_keyframes` keyframes with random
// poses (each observes about 60% of the points, with its descriptor perturbed), a vocabulary tree
// trained on the keyframes' descriptors (branching 4, depth 2) and its inverted file.
LocalizationMap SampleLocalizationMap(int num_points, int num_keyframes, unsigned seed);

// Sets the header's payload size and CRC-32 to those of the bytes after the 24-byte header (a file
// shorter than the header is left as it is).
void RepairMapHeader(std::string* file_bytes);

}  // namespace reconar::testing
