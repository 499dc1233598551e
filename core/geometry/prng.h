#pragma once
// SplitMix64 lives in core/base/prng.h (the features module draws from it too); this include
// keeps the geometry includes building.
#include "core/base/prng.h"
