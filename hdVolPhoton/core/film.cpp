#include "core/film.h"

#include <cmath>
#include <stdexcept>

namespace volphoton {

Film::Film(int width, int height) : width_(width), height_(height) {
    if (width <= 0 || height <= 0 || static_cast<long>(width) * height > (1L << 28))
        throw std::invalid_argument("film: resolution must be positive and at most 2^28 pixels");
    clear();
}

void Film::clear() {
    size_t n = static_cast<size_t>(width_) * height_;
    for (auto& b : rgb_) b.assign(3 * n, 0.0);
    alpha_.assign(n, 0.0);
    lumSq_.assign(n, 0.0);
    depth_.assign(n, std::numeric_limits<float>::infinity());
    count_.assign(n, 0);
    ids_.assign(n, PixelIds());
}

void Film::add(int x, int y, const PathRadiance& r) {
    size_t i = index(x, y);
    const Spectrum parts[RgbAovCount] = {r.beauty(), r.single, r.multiple, r.emission, r.surface, r.albedo, r.normal};
    for (int a = 0; a < RgbAovCount; ++a)
        for (int c = 0; c < 3; ++c) rgb_[a][3 * i + c] += parts[a][c];
    alpha_[i] += r.alpha;
    double lum = luminance(parts[Beauty]);
    lumSq_[i] += lum * lum;
    depth_[i] = std::min(depth_[i], static_cast<float>(r.depth));
    ++count_[i];
}

void Film::merge(const Film& o) {
    for (int a = 0; a < RgbAovCount; ++a)
        for (size_t i = 0; i < rgb_[a].size(); ++i) rgb_[a][i] += o.rgb_[a][i];
    for (size_t i = 0; i < alpha_.size(); ++i) {
        alpha_[i] += o.alpha_[i];
        lumSq_[i] += o.lumSq_[i];
        depth_[i] = std::min(depth_[i], o.depth_[i]);
        count_[i] += o.count_[i];
        if (ids_[i].object < 0) ids_[i] = o.ids_[i];
    }
}

std::vector<float> Film::resolveRgb(Aov aov) const {
    std::vector<float> out(rgb_[aov].size());
    for (size_t i = 0; i < count_.size(); ++i)
        for (int c = 0; c < 3; ++c) out[3 * i + c] = count_[i] ? static_cast<float>(rgb_[aov][3 * i + c] / count_[i]) : 0.0f;
    return out;
}

std::vector<float> Film::resolveAlpha() const {
    std::vector<float> out(alpha_.size());
    for (size_t i = 0; i < alpha_.size(); ++i) out[i] = count_[i] ? static_cast<float>(alpha_[i] / count_[i]) : 0.0f;
    return out;
}

std::vector<float> Film::resolveRelativeError() const {
    size_t n = count_.size();
    std::vector<double> mean(n, 0.0);
    double imageMean = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!count_[i]) continue;
        mean[i] = luminance(Spectrum(rgb_[Beauty][3 * i], rgb_[Beauty][3 * i + 1], rgb_[Beauty][3 * i + 2])) / count_[i];
        imageMean += mean[i];
    }
    double floor = ErrorFloor * imageMean / double(n);
    std::vector<float> out(n);
    for (size_t i = 0; i < n; ++i) {
        double c = count_[i];
        if (c < 2) {
            out[i] = std::numeric_limits<float>::infinity();
            continue;
        }
        double variance = std::max(0.0, lumSq_[i] / c - mean[i] * mean[i]) * c / (c - 1);
        double denominator = std::max(std::abs(mean[i]), floor);
        out[i] = variance == 0 ? 0.0f : denominator > 0 ? static_cast<float>(std::sqrt(variance / c) / denominator)
                                                       : std::numeric_limits<float>::infinity();
    }
    return out;
}

std::vector<float> Film::resolveDepth() const { return depth_; }

std::vector<int> Film::resolveIds(IdAov which) const {
    std::vector<int> out(ids_.size());
    for (size_t i = 0; i < ids_.size(); ++i)
        out[i] = which == ObjectId ? ids_[i].object : which == InstanceId ? ids_[i].instance : ids_[i].element;
    return out;
}

}  // namespace volphoton
