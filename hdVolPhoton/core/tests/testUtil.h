// Statistics helpers shared by the core tests.
#pragma once

#include <cmath>
#include <functional>
#include <vector>

namespace volphoton::test {

/// Mean and standard error of the mean over per-seed estimates.
struct MeanAndError {
    double mean = 0, stderr_ = 0;
};
inline MeanAndError meanAndError(const std::vector<double>& xs) {
    MeanAndError r;
    for (double x : xs) r.mean += x;
    r.mean /= xs.size();
    double var = 0;
    for (double x : xs) var += (x - r.mean) * (x - r.mean);
    var /= (xs.size() - 1);
    r.stderr_ = std::sqrt(var / xs.size());
    return r;
}

/// Runs `estimate(seed)` for `seeds` seeds; each returns the mean of many samples for that seed.
inline MeanAndError overSeeds(int seeds, const std::function<double(int)>& estimate) {
    std::vector<double> xs;
    for (int s = 0; s < seeds; ++s) xs.push_back(estimate(s));
    return meanAndError(xs);
}

}  // namespace volphoton::test
