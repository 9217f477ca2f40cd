#include "sampling/piecewise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "chi2.h"
#include "core/frame.h"

namespace hairis {
namespace {

// Number of χ² tests in this file, for the Šidák correction.
constexpr int kChi2Tests = 2;

float next_up(float x) { return std::nextafter(x, std::numeric_limits<float>::infinity()); }
float next_down(float x) { return std::nextafter(x, -std::numeric_limits<float>::infinity()); }

// A bumpy density with runs of zero cells, a spike and cells of tiny mass.
std::vector<float> bumpy_values(int n) {
    std::vector<float> v(size_t(n), 0.0f);
    for (int k = 0; k < n; ++k) {
        const double x = (k + 0.5) / n;
        v[size_t(k)] =
            float(0.2 + std::pow(std::sin(9.0 * x), 2) + 3.0 * std::exp(-sqr((x - 0.7) / 0.03)));
    }
    for (int k : {0, 1, 7, 8, 9, n - 1}) v[size_t(k)] = 0.0f;  // zero runs, at both ends too
    v[12] = 1e-7f;                                             // tiny but positive
    v[13] = 1e-30f;
    return v;
}

// Random floats in [0, 1) plus the awkward ones: 0, 1, the smallest, the largest below 1,
// and every stored CDF value and its float neighbours (the cell boundaries in u).
std::vector<float> test_uniforms(const PiecewiseConstant1D &d, int random_count) {
    std::vector<float> u = {
        0.0f, std::numeric_limits<float>::denorm_min(), 1e-9f, 1e-7f, 0.5f, next_down(1.0f), 1.0f};
    for (int k = 0; k <= d.cell_count(); ++k) {
        const float c = d.cdf_at(k);
        for (float v : {c, next_up(c), next_down(c)})
            if (v >= 0.0f && v <= 1.0f) u.push_back(v);
    }
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    for (int i = 0; i < random_count; ++i) u.push_back(uniform(rng));
    return u;
}

PiecewiseConstant1D make_1d(const std::vector<float> &values, float lo, float hi) {
    Expected<PiecewiseConstant1D> d = PiecewiseConstant1D::create(values, lo, hi);
    EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message);
    return std::move(d).value();
}

TEST(PiecewiseConstant1D, SampleAndPdfDescribeTheSameDensity) {
    const std::vector<float> values = bumpy_values(37);
    const PiecewiseConstant1D d = make_1d(values, -1.3f, 2.1f);
    long long mismatched_bits = 0;
    for (float u : test_uniforms(d, 100000)) {
        const PiecewiseSample1D s = d.sample(u);
        ASSERT_TRUE(s.x >= d.lo() && s.x <= d.hi()) << "u = " << u;
        ASSERT_GT(s.pdf, 0.0f) << "u = " << u;
        ASSERT_GT(values[size_t(s.cell)], 0.0f)
            << "zero-value cell " << s.cell << " sampled, u = " << u;
        ASSERT_EQ(d.cells().cell_of(s.x), s.cell) << "u = " << u;
        const float p = d.pdf(s.x);
        ASSERT_NEAR(p, s.pdf, 1e-5f * s.pdf) << "u = " << u << ", x = " << s.x;
        mismatched_bits += p != s.pdf;
        // invert() is the CDF: it undoes sample() (u = 1 is clamped to just below 1).
        ASSERT_NEAR(d.invert(s.x), std::min(u, kOneMinusEpsilon), 1e-5f) << "x = " << s.x;
    }
    EXPECT_EQ(mismatched_bits, 0) << "sample() and pdf() should agree bit for bit";
}

TEST(PiecewiseConstant1D, PdfIsValueOverIntegral) {
    const std::vector<float> values = bumpy_values(37);
    const PiecewiseConstant1D d = make_1d(values, -1.3f, 2.1f);
    double sum = 0.0;
    for (float v : values) sum += v;
    const double width = (double(2.1f) - double(-1.3f)) / 37;
    EXPECT_NEAR(d.integral(), sum * width, 1e-9 * sum * width);
    double integral = 0.0;
    for (int k = 0; k < d.cell_count(); ++k) {
        const double expected = values[size_t(k)] / (sum * width);
        const float x = d.lo() + (k + 0.5f) * d.cells().width();
        if (values[size_t(k)] > 1e-3f) {
            EXPECT_NEAR(d.pdf(x), expected, 1e-5 * expected) << "cell " << k;
        }
        if (values[size_t(k)] == 0.0f) {
            EXPECT_EQ(d.pdf(x), 0.0f) << "cell " << k;
        }
        if (values[size_t(k)] > 0.0f) {
            EXPECT_GT(d.pdf(x), 0.0f) << "a positive cell lost its mass: " << k;
        }
        integral += double(d.cell_mass(k));
    }
    EXPECT_NEAR(integral, 1.0, 1e-6);
    EXPECT_EQ(d.pdf(next_down(d.lo())), 0.0f);
    EXPECT_EQ(d.pdf(next_up(d.hi())), 0.0f);
    EXPECT_EQ(d.pdf(std::numeric_limits<float>::quiet_NaN()), 0.0f);
    EXPECT_FALSE(d.is_uniform_fallback());
}

TEST(PiecewiseConstant1D, BoundariesBelongToTheUpperCell) {
    const std::vector<float> values = {1.0f, 2.0f, 0.0f, 3.0f, 4.0f, 5.0f, 6.0f};
    const PiecewiseConstant1D d = make_1d(values, 0.1f, 0.8f);  // widths not representable
    const UniformCells &c = d.cells();
    for (int k = 0; k < d.cell_count(); ++k) {
        EXPECT_EQ(c.cell_of(c.edge(k)), k);
        if (k > 0) {
            EXPECT_EQ(c.cell_of(next_down(c.edge(k))), k - 1);
        }
        EXPECT_EQ(d.pdf(c.edge(k)), d.cell_pdf(k));
        if (values[size_t(k)] > 0.0f) {
            // u exactly at the CDF step lands exactly on the cell's lower boundary.
            const PiecewiseSample1D s = d.sample(d.cdf_at(k));
            EXPECT_EQ(s.cell, k);
            EXPECT_EQ(s.x, c.edge(k));
        }
    }
    EXPECT_EQ(d.pdf(d.hi()), d.cell_pdf(d.cell_count() - 1));  // hi closes the last cell
    EXPECT_EQ(d.sample(0.0f).x, d.lo());
    EXPECT_LE(d.sample(1.0f).x, d.hi());
    EXPECT_EQ(d.invert(d.lo()), 0.0f);
    EXPECT_EQ(d.invert(d.hi()), 1.0f);
}

TEST(PiecewiseConstant1D, ZeroMassCellsAreNeverSampled) {
    const std::vector<float> values = {0, 0, 5, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0};
    const PiecewiseConstant1D d = make_1d(values, 0.0f, 1.0f);
    std::vector<long long> hits(values.size(), 0);
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    for (int i = 0; i < 100000; ++i) ++hits[size_t(d.sample(uniform(rng)).cell)];
    for (size_t k = 0; k < values.size(); ++k) {
        if (values[k] == 0.0f) {
            EXPECT_EQ(hits[k], 0) << "cell " << k;
        } else
            EXPECT_NEAR(double(hits[k]) / 100000.0, values[k] / 8.0, 0.01) << "cell " << k;
    }
}

TEST(PiecewiseConstant1D, Chi2OnBumpyDensity) {
    const PiecewiseConstant1D d = make_1d(bumpy_values(37), -1.3f, 2.1f);
    testing::Chi2Options options;
    // The density jumps inside χ² cells (by 10× at the spike): Simpson's rule needs many nodes
    // there to get the expected counts right, and in 1D they are cheap.
    options.simpson_points = 20001;
    options.test_count = kChi2Tests;
    options.seed = 0x1d;
    const testing::Chi2Result r = testing::chi2_interval_test(
        [&](double u) -> std::optional<double> { return double(d.sample(float(u)).x); },
        [&](double x) { return double(d.pdf(float(x))); }, -1.3, 2.1, 50, options);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
    std::printf("[chi2] PiecewiseConstant1D bumpy: %s\n", r.message.c_str());
}

TEST(PiecewiseConstant1D, GuideTableHandlesConcentratedMass) {
    // 100 000 cells, almost all the mass in one of them and many tiny cells around it: the
    // guide entries all point near the spike, the walk still finds the right cell.
    std::vector<float> values(100000, 1e-6f);
    values[73000] = 1e6f;
    for (int k = 0; k < 50000; k += 2) values[size_t(k)] = 0.0f;
    const PiecewiseConstant1D d = make_1d(values, 0.0f, 1.0f);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    int spike = 0;
    for (int i = 0; i < 100000; ++i) {
        const float u = uniform(rng);
        const PiecewiseSample1D s = d.sample(u);
        ASSERT_GT(values[size_t(s.cell)], 0.0f);
        ASSERT_GE(u, d.cdf_at(s.cell));
        ASSERT_LT(u, d.cdf_at(s.cell + 1));
        ASSERT_EQ(d.pdf(s.x), s.pdf);
        spike += s.cell == 73000;
    }
    EXPECT_GT(spike, 99000);
}

TEST(PiecewiseConstant1D, ZeroMassFallsBackToUniform) {
    const PiecewiseConstant1D d = make_1d(std::vector<float>(10, 0.0f), -2.0f, 3.0f);
    EXPECT_TRUE(d.is_uniform_fallback());
    EXPECT_EQ(d.integral(), 0.0);
    for (float x : {-2.0f, -1.0f, 0.3f, 2.99f, 3.0f}) EXPECT_NEAR(d.pdf(x), 0.2f, 1e-6f);
    for (float u : {0.0f, 0.25f, 0.5f, 0.999f}) {
        const PiecewiseSample1D s = d.sample(u);
        EXPECT_NEAR(s.x, -2.0f + 5.0f * u, 1e-5f);
        EXPECT_NEAR(s.pdf, 0.2f, 1e-6f);
    }
    EXPECT_FALSE(make_1d({0.0f, 1.0f}, 0.0f, 1.0f).is_uniform_fallback());
}

TEST(PiecewiseConstant1D, RefusesInvalidInput) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    auto error_of = [](Expected<PiecewiseConstant1D> d) {
        return d.ok() ? std::string("(accepted)") : d.error().message;
    };
    EXPECT_NE(error_of(PiecewiseConstant1D::create({1.0f, nan, 2.0f}, 0.0f, 1.0f))
                  .find("values[1] must be finite"),
              std::string::npos);
    EXPECT_NE(
        error_of(PiecewiseConstant1D::create({1.0f, 2.0f, inf}, 0.0f, 1.0f)).find("values[2]"),
        std::string::npos);
    EXPECT_NE(error_of(PiecewiseConstant1D::create({1.0f, -0.5f}, 0.0f, 1.0f))
                  .find("values[1] must be finite and >= 0"),
              std::string::npos);
    EXPECT_NE(
        error_of(PiecewiseConstant1D::create(std::vector<float>{}, 0.0f, 1.0f)).find("cell count"),
        std::string::npos);
    const float one = 1.0f;  // never read: the count is refused first
    EXPECT_NE(error_of(PiecewiseConstant1D::create(&one, UniformCells::kMaxCells + 1, 0.0f, 1.0f))
                  .find("cell count"),
              std::string::npos);
    EXPECT_NE(
        error_of(PiecewiseConstant1D::create({1.0f}, 1.0f, 1.0f)).find("upper end > lower end"),
        std::string::npos);
    EXPECT_NE(error_of(PiecewiseConstant1D::create({1.0f}, nan, 1.0f)).find("must be finite"),
              std::string::npos);
    EXPECT_NE(error_of(PiecewiseConstant1D::create({1.0f, 1.0f, 1.0f, 1.0f}, 1.0f, next_up(1.0f)))
                  .find("too narrow"),
              std::string::npos);
    EXPECT_NE(error_of(PiecewiseConstant1D::create(nullptr, 3, 0.0f, 1.0f)).find("null"),
              std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// PiecewiseConstant2D

constexpr int kRows = 60, kCols = 97;

// Over θ ∈ [−π/2, π/2] (rows) × φ ∈ [−π, π] (columns); rows near the poles and one in the
// middle are zero, so the density per steradian stays bounded.
std::vector<float> grid_values() {
    std::vector<float> v(size_t(kRows) * kCols, 0.0f);
    for (int r = 4; r < kRows - 4; ++r) {
        if (r == 28) continue;
        for (int c = 0; c < kCols; ++c) {
            const double x = (r + 0.5) / kRows, y = (c + 0.5) / kCols;
            v[size_t(r) * kCols + size_t(c)] =
                float(0.1 + std::exp(-sqr((x - 0.35) / 0.15) - sqr((y - 0.6) / 0.2)) +
                      0.5 * sqr(std::sin(7 * y)));
        }
    }
    v[size_t(10) * kCols + 5] = 0.0f;  // a single zero cell
    return v;
}

PiecewiseConstant2D make_2d(const std::vector<float> &v) {
    Expected<PiecewiseConstant2D> d = PiecewiseConstant2D::create(
        v, kRows, kCols, -float(kHalfPi), float(kHalfPi), -float(kPi), float(kPi));
    EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message);
    return std::move(d).value();
}

TEST(PiecewiseConstant2D, SampleAndPdfDescribeTheSameDensity) {
    const std::vector<float> v = grid_values();
    const PiecewiseConstant2D d = make_2d(v);
    std::mt19937 rng(77);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const float edge_u[] = {0.0f, 1e-8f, 0.5f, next_down(1.0f), 1.0f};
    for (int i = 0; i < 100000 + 25; ++i) {
        const float u0 = i < 25 ? edge_u[i / 5] : uniform(rng);
        const float u1 = i < 25 ? edge_u[i % 5] : uniform(rng);
        const PiecewiseSample2D s = d.sample(u0, u1);
        ASSERT_GT(v[size_t(s.row) * kCols + size_t(s.col)], 0.0f) << "a zero cell was sampled";
        ASSERT_FALSE(d.row_is_empty(s.row));
        ASSERT_GT(s.pdf, 0.0f);
        ASSERT_NEAR(d.pdf(s.x, s.y), s.pdf, 1e-5f * s.pdf);
        const Point2 back = d.invert(s.x, s.y);
        ASSERT_NEAR(back.u0, std::min(u0, kOneMinusEpsilon), 1e-5f);
        ASSERT_NEAR(back.u1, std::min(u1, kOneMinusEpsilon), 1e-4f);  // via the row's CDF
    }
    EXPECT_TRUE(d.row_is_empty(0));
    EXPECT_TRUE(d.row_is_empty(28));
    EXPECT_FALSE(d.is_uniform_fallback());
}

TEST(PiecewiseConstant2D, PdfIsValueOverIntegral) {
    const std::vector<float> v = grid_values();
    const PiecewiseConstant2D d = make_2d(v);
    double sum = 0.0;
    std::vector<double> row_sum(kRows, 0.0);
    for (int r = 0; r < kRows; ++r)
        for (int c = 0; c < kCols; ++c) row_sum[size_t(r)] += v[size_t(r) * kCols + size_t(c)];
    for (double x : row_sum) sum += x;
    const double area = (double(float(kPi)) * double(float(kTwoPi))) / (double(kRows) * kCols);
    for (int r = 0; r < kRows; ++r)
        for (int c = 0; c < kCols; ++c) {
            const float x = d.x_cells().lo() + (r + 0.5f) * d.x_cells().width();
            const float y = d.y_cells().lo() + (c + 0.5f) * d.y_cells().width();
            const double value = v[size_t(r) * kCols + size_t(c)];
            const double expected = value / (sum * area);
            if (value == 0.0) {
                EXPECT_EQ(d.pdf(x, y), 0.0f);
                continue;
            }
            // The masses are differences of float CDF values in [0, 1]: each is exact to
            // about one float ulp of 1, 2^-24, so relatively to 2^-24 / mass.
            const double row_mass = row_sum[size_t(r)] / sum, col_mass = value / row_sum[size_t(r)];
            const double tolerance =
                expected * (1e-6 + 0x1p-23 * (1.0 / row_mass + 1.0 / col_mass));
            EXPECT_NEAR(d.pdf(x, y), expected, tolerance) << r << ", " << c;
        }
}

TEST(PiecewiseConstant2D, Chi2AsDirections) {
    // Sampled (θ, φ) as directions: the density per steradian is pdf(θ, φ) / cos θ.
    const PiecewiseConstant2D d = make_2d(grid_values());
    testing::Chi2Options options;
    options.simpson_points = 65;  // the density jumps inside χ² cells
    options.test_count = kChi2Tests;
    options.seed = 0x2d;  // independent of the 1D test's numbers
    const testing::Chi2Result r = testing::chi2_direction_test(
        [&](testing::Sample3 u) -> std::optional<Vec3> {
            const PiecewiseSample2D s = d.sample(u.u0, u.u1);
            return direction_of(s.x, s.y);
        },
        [&](Vec3 w) {
            const FiberAngles a = angles_of(w);
            const double c = std::cos(double(a.theta));
            return c > 0.0 ? double(d.pdf(a.theta, a.phi)) / c : 0.0;
        },
        options);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
    std::printf("[chi2] PiecewiseConstant2D as directions: %s\n", r.message.c_str());
}

TEST(PiecewiseConstant2D, ZeroMassFallsBackToUniform) {
    const PiecewiseConstant2D d = make_2d(std::vector<float>(size_t(kRows) * kCols, 0.0f));
    EXPECT_TRUE(d.is_uniform_fallback());
    const float uniform = float(1.0 / (kPi * kTwoPi));
    for (float u : {0.0f, 0.3f, 0.9f}) {
        const PiecewiseSample2D s = d.sample(u, 1.0f - u);
        EXPECT_NEAR(s.pdf, uniform, 1e-5f * uniform);
        EXPECT_NEAR(s.x, -float(kHalfPi) + float(kPi) * u, 1e-5f);
    }
}

TEST(PiecewiseConstant2D, RefusesInvalidInput) {
    std::vector<float> v = grid_values();
    auto error_of = [](Expected<PiecewiseConstant2D> d) {
        return d.ok() ? std::string("(accepted)") : d.error().message;
    };
    EXPECT_NE(error_of(PiecewiseConstant2D::create(v, kRows, kCols + 1, 0, 1, 0, 1))
                  .find("rows × columns"),
              std::string::npos);
    EXPECT_NE(error_of(PiecewiseConstant2D::create(v, 0, kCols, 0, 1, 0, 1)).find("row count"),
              std::string::npos);
    EXPECT_NE(error_of(PiecewiseConstant2D::create(v, kRows, kCols, 0, 1, 2, 1)).find("y axis"),
              std::string::npos);
    EXPECT_NE(error_of(PiecewiseConstant2D::create({}, 1 << 20, 1 << 20, 0, 1, 0, 1))
                  .find("exceeds the limit"),
              std::string::npos);
    v[size_t(3) * kCols + 4] = -1.0f;
    EXPECT_NE(error_of(PiecewiseConstant2D::create(v, kRows, kCols, 0, 1, 0, 1))
                  .find("values[" + std::to_string(3 * kCols + 4) + "]"),
              std::string::npos);
}

}  // namespace
}  // namespace hairis
