#include "render/pixel_filter.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/math.h"

namespace hairis {

namespace {

float filter_value(PixelFilterType type, float x, float width) {
    switch (type) {
        case PixelFilterType::Gaussian: {
            const float v = x * (6.0f / width);
            return std::exp(-2.0f * v * v);
        }
        case PixelFilterType::BlackmanHarris: {
            const float v = float(2.0 * kPi) * (x / width + 0.5f);
            return 0.35875f - 0.48829f * std::cos(v) + 0.14128f * std::cos(2.0f * v) -
                   0.01168f * std::cos(3.0f * v);
        }
        case PixelFilterType::Box: break;
    }
    return 1.0f;
}

}  // namespace

PixelFilter::PixelFilter(PixelFilterType type, float width) {
    if (type == PixelFilterType::Box && width == 1.0f) {
        identity_ = true;
        return;
    }
    // Cycles widens the filter's own width before tabulating it.
    const float filter_width = type == PixelFilterType::Gaussian       ? 3.0f * width
                               : type == PixelFilterType::BlackmanHarris ? 2.0f * width
                                                                         : width;
    const float range = 0.5f * filter_width;
    // util_cdf_evaluate at resolution kTableSize − 1.
    const int resolution = kTableSize - 1;
    std::vector<float> cdf(std::size_t(resolution) + 1, 0.0f);
    for (int i = 0; i < resolution; ++i) {
        const float x = range * float(i) / float(resolution - 1);
        cdf[std::size_t(i) + 1] = cdf[std::size_t(i)] + std::fabs(filter_value(type, x, filter_width));
    }
    const float total = cdf[std::size_t(resolution)];
    const float scale = total == 0.0f ? 0.0f : 1.0f / total;
    for (float &c : cdf) c *= scale;
    cdf[std::size_t(resolution)] = 1.0f;
    // util_cdf_invert with make_symmetric.
    const int cdf_size = int(cdf.size());
    const int half = (kTableSize - 1) / 2;
    for (int i = 0; i <= half; ++i) {
        const float x = float(i) / float(half);
        int index = int(std::upper_bound(cdf.begin(), cdf.end(), x) - cdf.begin());
        float t = 0.0f;
        if (index < cdf_size - 1) {
            t = (x - cdf[std::size_t(index)]) / (cdf[std::size_t(index) + 1] - cdf[std::size_t(index)]);
        } else {
            index = cdf_size - 1;
        }
        const float y = ((float(index) + t) / float(kTableSize - 1)) * (2.0f * range);
        table_[std::size_t(half + i)] = 0.5f * (1.0f + y);
        table_[std::size_t(half - i)] = 0.5f * (1.0f - y);
    }
}

float PixelFilter::position(float u) const {
    if (identity_) return u;
    // lookup_table_read.
    const float x = std::clamp(u, 0.0f, 1.0f) * float(kTableSize - 1);
    const int index = std::min(int(x), kTableSize - 1);
    const int next = std::min(index + 1, kTableSize - 1);
    const float t = x - float(index);
    return (1.0f - t) * table_[std::size_t(index)] + t * table_[std::size_t(next)];
}

}  // namespace hairis
