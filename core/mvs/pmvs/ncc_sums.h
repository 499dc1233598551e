#pragma once
// The three sums of an NCC evaluation (ncc.h); a plain struct with no standard-library includes so
// that the per-ISA kernel units (ncc_<isa>.cc) include nothing that could be emitted with wider
// instructions.

namespace reconar {

// sum(b), sum(b^2), sum(r b) over the samples b and the normalised reference r.
struct NccSums {
  float sum = 0.0f;
  float sum_squares = 0.0f;
  float sum_products = 0.0f;
};

}  // namespace reconar
