#pragma once
// Shared between flip.cpp and metrics.cpp; not part of the public interface.
#include <vector>

namespace mfr {

// Weighted percentile of already ascending-sorted values whose sum is total: the first value at
// which the running sum exceeds p × total (FLIP's pooling). Lets flip() sort once for three
// percentiles. Returns 0 for no values, the largest value when the threshold is never exceeded.
double weightedPercentileSorted(const std::vector<float>& sorted, double total, double p);

}  // namespace mfr
