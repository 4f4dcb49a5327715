#pragma once
// Pearson correlation between two maps over a pixel mask, for the relaxed relative depth loss
// 1 - corr(rendered inverse depth, monocular disparity) of SparseGS.
#include <cstddef>
#include <cstdint>

namespace iesrgs::loss {

// Correlation of a and b (count values each) over the entries where mask != 0 (all of them when
// mask is null). Undefined correlations (fewer than two entries, or either map constant over the
// mask) count as 0, with zero gradient, so such a view adds a constant to the loss.
template <typename T>
double pearson_correlation(const T* a, const T* b, const uint8_t* mask, size_t count);

// Adds scale * d corr / d a to grad_a (b is a constant target).
template <typename T>
void pearson_correlation_backward(const T* a, const T* b, const uint8_t* mask, size_t count,
                                  double scale, T* grad_a);

}  // namespace iesrgs::loss
