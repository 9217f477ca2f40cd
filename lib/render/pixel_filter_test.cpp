#include "render/pixel_filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "core/math.h"

namespace hairis {
namespace {

// The filter's shape as Blender documents it, about the pixel centre (offset x in pixels), and
// the half-width of its support: an independent statement of Cycles' three filters.
struct Shape {
    std::function<double(double)> f;
    double half_width;
};
Shape shape_of(PixelFilterType type, double width) {
    switch (type) {
        case PixelFilterType::Gaussian:
            // Cycles' Gaussian of width w: exp(−2(2x/w)²), cut at 1.5 w.
            return {[width](double x) { return std::exp(-8.0 * x * x / (width * width)); }, 1.5 * width};
        case PixelFilterType::BlackmanHarris:
            // The four-term Blackman-Harris window spanning 2w.
            return {[width](double x) {
                        const double t = 2.0 * kPi * (x / (2.0 * width) + 0.5);
                        return 0.35875 - 0.48829 * std::cos(t) + 0.14128 * std::cos(2 * t) - 0.01168 * std::cos(3 * t);
                    },
                    width};
        case PixelFilterType::Box: break;
    }
    return {[](double) { return 1.0; }, 0.5 * width};
}

// The CDF of the shape's normalized density at positions (pixel units, centre 0.5).
std::vector<double> shape_cdf(const Shape &s, const std::vector<double> &at) {
    const int n = 200000;
    std::vector<double> xs(n + 1), cdf(n + 1, 0.0);
    const double a = 0.5 - s.half_width, h = 2.0 * s.half_width / n;
    for (int i = 0; i <= n; ++i) xs[i] = a + h * i;
    for (int i = 1; i <= n; ++i) cdf[i] = cdf[i - 1] + 0.5 * h * (s.f(xs[i - 1] - 0.5) + s.f(xs[i] - 0.5));
    std::vector<double> out;
    for (double x : at) {
        const double t = std::clamp((x - a) / h, 0.0, double(n));
        const int i = std::min(int(t), n - 1);
        out.push_back((cdf[i] + (t - i) * (cdf[i + 1] - cdf[i])) / cdf[n]);
    }
    return out;
}

// The empirical CDF of the positions of evenly spread u.
std::vector<double> sample_cdf(const PixelFilter &filter, const std::vector<double> &at) {
    const int n = 400000;
    std::vector<float> p(n);
    for (int i = 0; i < n; ++i) p[std::size_t(i)] = filter.position((float(i) + 0.5f) / float(n));
    std::sort(p.begin(), p.end());
    std::vector<double> out;
    for (double x : at) out.push_back(double(std::upper_bound(p.begin(), p.end(), float(x)) - p.begin()) / n);
    return out;
}

double max_difference(const std::vector<double> &a, const std::vector<double> &b) {
    double m = 0;
    for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::fabs(a[i] - b[i]));
    return m;
}

TEST(PixelFilter, PositionsFollowEachFilterShape) {
    struct Case {
        PixelFilterType type;
        float width;
    };
    for (const Case c : {Case{PixelFilterType::BlackmanHarris, 1.5f}, Case{PixelFilterType::Gaussian, 1.5f},
                         Case{PixelFilterType::Box, 2.0f}, Case{PixelFilterType::BlackmanHarris, 4.0f}}) {
        const Shape shape = shape_of(c.type, c.width);
        std::vector<double> at;
        for (int i = 0; i <= 200; ++i) at.push_back(0.5 - shape.half_width + 2.0 * shape.half_width * i / 200.0);
        const PixelFilter filter(c.type, c.width);
        // The table has 1023 steps, and its last entry (0, as in Cycles) sends the top 1/1023
        // of u back across the pixel: both stay within 0.003 of the shape's CDF.
        EXPECT_LT(max_difference(sample_cdf(filter, at), shape_cdf(shape, at)), 0.003)
            << int(c.type) << " width " << c.width;
        // Symmetric about the centre, inside the support.
        for (int i = 0; i <= 1000; ++i) {
            const float u = float(i) / 1000.0f * (1022.0f / 1023.0f);
            const float p = filter.position(u), q = filter.position(1022.0f / 1023.0f - u);
            EXPECT_NEAR(p + q, 1.0f, 1e-4f);
            EXPECT_GE(p, 0.5f - float(shape.half_width) - 1e-4f);
            EXPECT_LE(p, 0.5f + float(shape.half_width) + 1e-4f);
        }
    }
    // The test tells the shapes apart: Gaussian and Blackman-Harris of the same width differ.
    std::vector<double> at;
    for (int i = 0; i <= 200; ++i) at.push_back(-1.75 + 4.5 * i / 200.0);
    EXPECT_GT(max_difference(shape_cdf(shape_of(PixelFilterType::Gaussian, 1.5), at),
                             shape_cdf(shape_of(PixelFilterType::BlackmanHarris, 1.5), at)),
              0.01);
}

TEST(PixelFilter, BoxOfOnePixelIsTheUniformSquare) {
    const PixelFilter box(PixelFilterType::Box, 1.0f);
    for (const float u : {0.0f, 0.25f, 0.5f, 0.999f}) EXPECT_EQ(box.position(u), u);
    // A wider box spreads samples evenly over its width about the centre.
    const PixelFilter wide(PixelFilterType::Box, 3.0f);
    EXPECT_NEAR(wide.position(0.0f), -1.0f, 1e-5f);
    EXPECT_NEAR(wide.position(511.0f / 1023.0f), 0.5f, 1e-5f);  // the table's centre entry
    EXPECT_NEAR(wide.position(0.75f), 1.25f, 5e-3f);
}

}  // namespace
}  // namespace hairis
