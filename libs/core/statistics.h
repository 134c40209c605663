// Order statistics of a sample: one definition of the median and of quantiles for the whole
// project (summaries, gates, reports).
#pragma once

#include <vector>

namespace jvl {

// Median: the middle value, or the mean of the two middle values for an even count. NaN if
// `values` is empty.
double Median(std::vector<double> values);

// Upper median: the value of rank floor(n / 2) (0-based) in sorted order, an element of the
// sample. NaN if `values` is empty.
double UpperMedian(std::vector<double> values);

// Nearest-rank quantile: the value of rank round(q (n - 1)) in sorted order, q in [0, 1]
// (clamped). NaN if `values` is empty.
double Quantile(std::vector<double> values, double q);

}  // namespace jvl
