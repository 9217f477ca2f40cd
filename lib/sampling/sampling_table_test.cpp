#include "sampling/sampling_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "core/frame.h"

namespace hairis {
namespace {

// The χ² tests in this file (Šidák family): direct 3 + multiple 3 × 5 strand counts +
// fallback slice 1 + coarse cells 2.
constexpr int kChi2Tests = 21;

constexpr int kNodes = 13;  // θ_r every 15° from −90° to 90°
constexpr int kThetaCells = 72;
constexpr int kPhiCells = 90;
const std::vector<int> kStrands = {1, 2, 4, 8, 16};
const std::vector<double> kStrandSigma = {0.44, 0.41, 0.37, 0.34, 0.29};  // the seed's Table 1

// θ_r values the tests visit: on a node (30°), between nodes, beyond 80° on both sides.
const float kOnNode = float(radians(30.0));
const float kBetweenNodes = 0.3f;
const float kGrazing = float(radians(84.0));
const float kGrazingNegative = float(radians(-86.5));

float next_down(float x) { return std::nextafter(x, -std::numeric_limits<float>::infinity()); }

std::vector<float> uniform_nodes() {
    std::vector<float> nodes(kNodes);
    for (int r = 0; r < kNodes; ++r) nodes[size_t(r)] = float(-kHalfPi + kPi * r / (kNodes - 1));
    return nodes;
}

double theta_center(int i) { return -kHalfPi + kPi * (i + 0.5) / kThetaCells; }
double phi_center(int j) { return -kPi + kTwoPi * (j + 0.5) / kPhiCells; }

// The seed's direct-scattering shape: a TT lobe at θ_i = −θ_r, φ = ±π, stretching in φ as θ_r
// grows, plus a wide band; per steradian, truncated to zero where it is negligible.
double direct_density(double theta_r, double theta_i, double phi) {
    const double sigma_phi = 0.52 + sqr(theta_r / kPi);
    const double lobe = std::exp(-sqr(theta_i + theta_r) / (2 * sqr(0.22)) -
                                 sqr(kPi - std::fabs(phi)) / (2 * sqr(sigma_phi)));
    const double band = 0.15 * std::exp(-sqr(theta_i + 0.8 * theta_r) / (2 * sqr(0.44)));
    const double v = lobe + band;
    return v < 1e-4 ? 0.0 : v;
}

// The seed's multiple-scattering band for n_h strands (its σ' made symmetric in θ_r).
double multiple_density(int strand, double theta_r, double theta_i) {
    const double sigma = kStrandSigma[size_t(strand)] + std::fabs(theta_r) / kPi;
    const double v = std::exp(-sqr(theta_i + 0.9 * theta_r) / (2 * sqr(sigma)));
    return v < 1e-4 ? 0.0 : v;
}

std::vector<float> direct_values(const std::vector<float> &nodes) {
    std::vector<float> v(nodes.size() * kThetaCells * kPhiCells);
    for (size_t r = 0; r < nodes.size(); ++r)
        for (int i = 0; i < kThetaCells; ++i)
            for (int j = 0; j < kPhiCells; ++j)
                v[(r * kThetaCells + size_t(i)) * kPhiCells + size_t(j)] =
                    float(direct_density(nodes[r], theta_center(i), phi_center(j)));
    return v;
}

std::vector<float> multiple_values(const std::vector<float> &nodes) {
    std::vector<float> v(nodes.size() * kStrands.size() * kThetaCells);
    for (size_t r = 0; r < nodes.size(); ++r)
        for (size_t k = 0; k < kStrands.size(); ++k)
            for (int i = 0; i < kThetaCells; ++i)
                v[(r * kStrands.size() + k) * kThetaCells + size_t(i)] =
                    float(multiple_density(int(k), nodes[r], theta_center(i)));
    return v;
}

template <typename T>
T unwrap(Expected<T> e) {
    if (!e.ok()) ADD_FAILURE() << e.error().message;
    return std::move(e).value();
}

const DirectTable &direct_table() {
    static const DirectTable t = unwrap(DirectTable::create(uniform_nodes(), kThetaCells, kPhiCells,
                                                            direct_values(uniform_nodes())));
    return t;
}

const MultipleTable &multiple_table() {
    static const MultipleTable t = unwrap(MultipleTable::create(
        uniform_nodes(), kStrands, kThetaCells, multiple_values(uniform_nodes())));
    return t;
}

// A sampler in the shape every table has: θ_o and three uniforms to a TableSample, the exact
// pdf_sin(θ_o, sin θ_i, φ) and the angle version pdf(θ_o, θ_i, φ).
struct Sampler {
    std::string name;
    std::function<TableSample(float, float, float, float)> sample;
    std::function<float(float, float, float)> pdf_sin;
    std::function<float(float, float, float)> pdf;
};

std::vector<Sampler> all_samplers() {
    std::vector<Sampler> s;
    s.push_back(
        {"direct",
         [](float t, float a, float b, float c) { return direct_table().sample(t, a, b, c); },
         [](float t, float x, float p) { return direct_table().pdf_sin(t, x, p); },
         [](float t, float ti, float p) { return direct_table().pdf(t, ti, p); }});
    for (size_t k = 0; k < kStrands.size(); ++k) {
        const int strand = int(k);
        s.push_back(
            {"multiple n_h=" + std::to_string(kStrands[k]),
             [strand](float t, float a, float b, float c) {
                 return multiple_table().sample(strand, t, a, b, c);
             },
             [strand](float t, float x, float) { return multiple_table().pdf_sin(strand, t, x); },
             [strand](float t, float ti, float p) {
                 return multiple_table().pdf(strand, t, ti, p);
             }});
    }
    return s;
}

// The χ² test of one sampler at one θ_o, with ω_o at azimuth phi_o.
testing::Chi2Result chi2(const Sampler &s, float theta_o, float phi_o = 0.0f) {
    // Each χ² test draws its own random numbers, so the family's tests are independent (as the
    // Šidák correction assumes): the seed depends on the sampler and θ_o.
    static_assert(sizeof(float) == sizeof(std::uint32_t));
    std::uint32_t theta_bits;
    std::memcpy(&theta_bits, &theta_o, sizeof theta_bits);
    testing::Chi2Options options;
    options.seed =
        std::hash<std::string>{}(s.name) ^ (std::uint64_t(theta_bits) * 0x9e3779b97f4a7c15ull);
    options.simpson_points = 33;  // the tabulated density jumps inside χ² cells
    options.test_count = kChi2Tests;
    const float cos_phi_o = std::cos(phi_o), sin_phi_o = std::sin(phi_o);
    const testing::Chi2Result r = testing::chi2_direction_test(
        [&](testing::Sample3 u) -> std::optional<Vec3> {
            const TableSample t = s.sample(theta_o, u.u0, u.u1, u.u2);
            if (!(t.pdf > 0.0f)) return std::nullopt;
            return t.local_direction(cos_phi_o, sin_phi_o);
        },
        [&](Vec3 w) {
            const float phi = relative_azimuth(std::atan2(w.z, w.y), phi_o);
            return double(s.pdf_sin(theta_o, w.x, phi));  // sin θ_i = ω_i.x
        },
        options);
    std::printf("[chi2] %-16s theta_o = %8.3f deg: %s\n", s.name.c_str(), degrees(theta_o),
                r.message.c_str());
    return r;
}

void expect_chi2(const Sampler &s, float theta_o, float phi_o = 0.0f) {
    const testing::Chi2Result r = chi2(s, theta_o, phi_o);
    EXPECT_TRUE(r.passed) << s.name << " at theta_o = " << theta_o << ": " << r.message;
    EXPECT_EQ(r.failed_samples, 0) << s.name;
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << s.name;
}

// ---------------------------------------------------------------------------------------------
// χ² goodness of fit

TEST(DirectTable, Chi2OnNode) {
    ASSERT_EQ(direct_table().theta_r_nodes()[8], kOnNode);
    expect_chi2(all_samplers()[0], kOnNode);
}

TEST(DirectTable, Chi2BetweenNodesInCyclesFrame) {
    expect_chi2(all_samplers()[0], kBetweenNodes, -float(kHalfPi));  // Cycles: φ_o = −π/2
}

TEST(DirectTable, Chi2Grazing) { expect_chi2(all_samplers()[0], kGrazing); }

TEST(MultipleTable, Chi2OnNode) {
    for (size_t k = 0; k < kStrands.size(); ++k) expect_chi2(all_samplers()[1 + k], kOnNode);
}

TEST(MultipleTable, Chi2BetweenNodes) {
    for (size_t k = 0; k < kStrands.size(); ++k) expect_chi2(all_samplers()[1 + k], kBetweenNodes);
}

TEST(MultipleTable, Chi2Grazing) {
    for (size_t k = 0; k < kStrands.size(); ++k)
        expect_chi2(all_samplers()[1 + k], kGrazingNegative);
}


TEST(SamplingTables, Chi2CoarseCellsAreUniformPerSteradian) {
    // With 30° cells the density inside a cell must still be constant per steradian (sin θ
    // uniform, not θ): near the poles the difference is large, unlike in the fine tables above.
    const std::vector<float> nodes = {-float(kHalfPi), 0.0f, float(kHalfPi)};
    std::vector<float> direct(3 * 6 * 8), multiple(3 * 1 * 6);
    for (size_t n = 0; n < direct.size(); ++n) direct[n] = float((n * 7919) % 13);  // some zeros
    for (size_t n = 0; n < multiple.size(); ++n) multiple[n] = float(1 + (n * 31) % 5);
    const DirectTable d = unwrap(DirectTable::create(nodes, 6, 8, direct));
    const MultipleTable m = unwrap(MultipleTable::create(nodes, {3}, 6, multiple));
    expect_chi2(
        {"coarse direct", [&](float t, float a, float b, float c) { return d.sample(t, a, b, c); },
         [&](float t, float x, float p) { return d.pdf_sin(t, x, p); },
         [&](float t, float ti, float p) { return d.pdf(t, ti, p); }},
        0.4f);
    expect_chi2({"coarse multiple",
                 [&](float t, float a, float b, float c) { return m.sample(0, t, a, b, c); },
                 [&](float t, float x, float) { return m.pdf_sin(0, t, x); },
                 [&](float t, float ti, float p) { return m.pdf(0, t, ti, p); }},
                0.0f);
}

// ---------------------------------------------------------------------------------------------
// Exactness of sample() against pdf()

TEST(SamplingTables, PdfOfSampleMatchesSamplePdf) {
    const float thetas[] = {
        -float(kHalfPi), -1.5f,    kGrazingNegative,          -0.7f,         0.0f, kBetweenNodes,
        kOnNode,         kGrazing, next_down(float(kHalfPi)), float(kHalfPi)};
    const float edge_u[] = {0.0f, 1e-9f, 1e-7f, 0.5f, next_down(1.0f), 1.0f};
    std::mt19937 rng(2024);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    for (const Sampler &s : all_samplers()) {
        long long bit_mismatches = 0, angle_checks = 0;
        const int n_samples = 100000;
        for (int n = 0; n < n_samples; ++n) {
            const float theta_o = thetas[size_t(n) % std::size(thetas)];
            float u0 = uniform(rng), u1 = uniform(rng), u2 = uniform(rng);
            if (n < 216) {  // every combination of awkward uniforms first
                u0 = edge_u[n % 6];
                u1 = edge_u[(n / 6) % 6];
                u2 = edge_u[(n / 36) % 6];
            }
            const TableSample t = s.sample(theta_o, u0, u1, u2);
            ASSERT_TRUE(std::isfinite(t.pdf) && t.pdf > 0.0f)
                << s.name << ": u = " << u0 << ", " << u1 << ", " << u2
                << ", theta_o = " << theta_o;
            ASSERT_LE(std::fabs(t.sin_theta_i), 1.0f);
            ASSERT_GE(t.cos_theta_i, 0.0f);
            ASSERT_LE(std::fabs(t.phi), float(kPi));
            ASSERT_NEAR(sqr(t.sin_theta_i) + sqr(t.cos_theta_i), 1.0f, 1e-6f);
            ASSERT_NEAR(t.cos_phi, std::cos(t.phi), 3e-7f) << t.phi;
            ASSERT_NEAR(t.sin_phi, std::sin(t.phi), 3e-7f) << t.phi;
            const float p = s.pdf_sin(theta_o, t.sin_theta_i, t.phi);
            ASSERT_NEAR(p, t.pdf, 1e-5f * t.pdf)
                << s.name << ": theta_o = " << theta_o << ", sin theta_i = " << t.sin_theta_i
                << ", phi = " << t.phi;
            bit_mismatches += p != t.pdf;
            // The angle version agrees whenever sin(θ_i) recovers the sampled sin θ_i exactly
            // (otherwise the rounding may cross a cell boundary).
            const float theta_i = t.theta_i();
            if (std::sin(theta_i) == t.sin_theta_i) {
                ++angle_checks;
                ASSERT_EQ(s.pdf(theta_o, theta_i, t.phi), t.pdf)
                    << s.name << ": theta_i = " << theta_i;
            }
        }
        EXPECT_EQ(bit_mismatches, 0)
            << s.name << ": sample() and pdf_sin() should agree bit for bit";
        EXPECT_GT(angle_checks, n_samples / 2) << s.name;
    }
}

TEST(SamplingTables, DirectionRoundTripsThroughTheFiberFrame) {
    // A caller with a frame and ω_o: ω_i from local_direction(φ_o), back to angles.
    const FiberFrame frame = FiberFrame::from_tangent_and_view(safe_normalize(Vec3{0.2f, 1.0f, 0.3f}),
                                                               safe_normalize(Vec3{-0.4f, 0.5f, 0.8f}));
    const Vec3 wo = safe_normalize(Vec3{-0.4f, 0.5f, 0.8f});
    const FiberAngles o = angles_of(frame.to_local(wo));
    EXPECT_NEAR(o.phi, -float(kHalfPi), 1e-5f);  // Cycles' frame
    std::mt19937 rng(8);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    for (int n = 0; n < 1000; ++n) {
        const TableSample t = direct_table().sample(o.theta, uniform(rng), uniform(rng), uniform(rng));
        const Vec3 wi = frame.to_world(t.local_direction(o.phi));
        ASSERT_NEAR(length(wi), 1.0f, 1e-5f);
        const Vec3 trig_free = t.local_direction(0.0f, -1.0f);  // φ_o = −π/2 without cos/sin
        const Vec3 l = frame.to_local(wi);
        ASSERT_NEAR(trig_free.x, l.x, 1e-5f);
        ASSERT_NEAR(trig_free.y, l.y, 1e-5f);
        ASSERT_NEAR(trig_free.z, l.z, 1e-5f);
        const FiberAngles i = angles_of(l);
        ASSERT_NEAR(i.theta, t.theta_i(), 2e-3f);
        if (t.cos_theta_i > 1e-2f) {
            ASSERT_NEAR(std::fabs(wrap_angle(relative_azimuth(i.phi, o.phi) - t.phi)), 0.0f, 1e-3f);
        }
    }
}

// ∫ pdf dω by a midpoint rule in (sin θ, φ), where dω = d(sin θ) dφ.
double sphere_integral(const Sampler &s, float theta_o) {
    constexpr int nx = 1200, ny = 1200;
    double sum = 0.0;
    for (int a = 0; a < nx; ++a) {
        const float theta_i = float(std::asin(-1.0 + 2.0 * (a + 0.5) / nx));
        for (int b = 0; b < ny; ++b)
            sum += s.pdf(theta_o, theta_i, float(-kPi + kTwoPi * (b + 0.5) / ny));
    }
    return sum * (2.0 / nx) * (kTwoPi / ny);
}

TEST(SamplingTables, PdfIntegratesToOneOverTheSphere) {
    for (const Sampler &s : all_samplers())
        for (float theta_o : {-float(kHalfPi), kOnNode, kBetweenNodes, kGrazing, 1.2345f})
            EXPECT_NEAR(sphere_integral(s, theta_o), 1.0, 1e-3)
                << s.name << " at theta_o = " << theta_o;
}

TEST(DirectTable, PdfIsValueOverSolidAngleIntegral) {
    // On a node the density per steradian is value / Σ value × (Δ sin θ) Δφ, independently of
    // how the sampler factors it.
    const DirectTable &t = direct_table();
    const int r = 8;
    double total = 0.0;
    for (int i = 0; i < kThetaCells; ++i) {
        const double ds = std::sin(-kHalfPi + kPi * (i + 1) / kThetaCells) -
                          std::sin(-kHalfPi + kPi * i / kThetaCells);
        for (int j = 0; j < kPhiCells; ++j)
            total += double(t.value(r, i, j)) * ds * (kTwoPi / kPhiCells);
    }
    int checked = 0;
    for (int i = 0; i < kThetaCells; ++i)
        for (int j = 0; j < kPhiCells; ++j) {
            const double expected = t.value(r, i, j) / total;
            const float p = t.pdf(kOnNode, float(theta_center(i)), float(phi_center(j)));
            if (t.value(r, i, j) == 0.0f) {
                EXPECT_EQ(p, 0.0f);
            } else if (expected > 1e-2) {
                EXPECT_NEAR(p, expected, 1e-4 * expected) << i << ", " << j;
                ++checked;
            }
        }
    EXPECT_GT(checked, 100);
}

TEST(SamplingTables, BetweenNodesThePdfIsTheBlendOfTheNeighbours) {
    const DirectTable &t = direct_table();
    const float lo = t.theta_r_nodes()[6], hi = t.theta_r_nodes()[7];  // 0° and 15°
    const float theta_o = kBetweenNodes - 0.05f;
    const float w = (theta_o - lo) / (hi - lo);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> ti(-1.57f, 1.57f), ph(-3.14f, 3.14f);
    for (int n = 0; n < 10000; ++n) {
        const float a = ti(rng), b = ph(rng);
        const float expected = (1 - w) * t.pdf(lo, a, b) + w * t.pdf(hi, a, b);
        ASSERT_NEAR(t.pdf(theta_o, a, b), expected, 1e-6f * expected + 1e-12f);
        const float m =
            (1 - w) * multiple_table().pdf(2, lo, a) + w * multiple_table().pdf(2, hi, a);
        ASSERT_NEAR(multiple_table().pdf(2, theta_o, a), m, 1e-6f * m + 1e-12f);
    }
    // Outside the node range θ_r is clamped.
    EXPECT_EQ(t.pdf(-2.0f, 0.1f, 3.0f), t.pdf(-float(kHalfPi), 0.1f, 3.0f));
    EXPECT_EQ(t.pdf(std::numeric_limits<float>::quiet_NaN(), 0.1f, 3.0f),
              t.pdf(-float(kHalfPi), 0.1f, 3.0f));
    // φ is wrapped; θ_i outside the sphere has no density.
    EXPECT_EQ(t.pdf(0.2f, 0.1f, 3.0f), t.pdf(0.2f, 0.1f, 3.0f - float(kTwoPi)));
    EXPECT_EQ(t.pdf(0.2f, 1.6f, 3.0f), 0.0f);
    EXPECT_EQ(t.pdf(0.2f, std::numeric_limits<float>::quiet_NaN(), 3.0f), 0.0f);
}

// ---------------------------------------------------------------------------------------------
// Zero mass

TEST(SamplingTables, ZeroMassSlicesSampleTheUniformSphere) {
    std::vector<float> nodes = uniform_nodes();
    std::vector<float> direct = direct_values(nodes);
    std::vector<float> multiple = multiple_values(nodes);
    const int r = 5;
    std::fill(direct.begin() + r * kThetaCells * kPhiCells,
              direct.begin() + (r + 1) * kThetaCells * kPhiCells, 0.0f);
    std::fill(multiple.begin() + (r * 5 + 3) * kThetaCells,
              multiple.begin() + (r * 5 + 4) * kThetaCells, 0.0f);
    const DirectTable d = unwrap(DirectTable::create(nodes, kThetaCells, kPhiCells, direct));
    const MultipleTable m = unwrap(MultipleTable::create(nodes, kStrands, kThetaCells, multiple));
    for (int k = 0; k < kNodes; ++k) EXPECT_EQ(d.slice_is_fallback(k), k == r);
    EXPECT_TRUE(m.slice_is_fallback(r, 3));
    EXPECT_FALSE(m.slice_is_fallback(r, 2));
    EXPECT_EQ(d.value(r, 30, 40), 0.0f);  // the raw values are kept as given
    const float node = nodes[size_t(r)];
    // 1/(4π) up to the float rounding of the uniform CDFs (steps of 1/72 and 1/90).
    const float uniform = float(kInvFourPi), tolerance = 5e-5f * uniform;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int n = 0; n < 10000; ++n) {
        const TableSample s = d.sample(node, u(rng), u(rng), u(rng));
        ASSERT_NEAR(s.pdf, uniform, tolerance);
        ASSERT_EQ(d.pdf_sin(node, s.sin_theta_i, s.phi), s.pdf);
        const TableSample t = m.sample(3, node, u(rng), u(rng), u(rng));
        ASSERT_NEAR(t.pdf, uniform, tolerance);
    }
    const Sampler fallback{"fallback slice",
                           [&](float t, float a, float b, float c) { return d.sample(t, a, b, c); },
                           [&](float t, float x, float p) { return d.pdf_sin(t, x, p); },
                           [&](float t, float ti, float p) { return d.pdf(t, ti, p); }};
    expect_chi2(fallback, node);
}

TEST(SamplingTables, ZeroValueCellsAreNeverSampled) {
    // The synthetic densities are truncated to zero far from their lobes.
    const DirectTable &t = direct_table();
    const MultipleTable &m = multiple_table();
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int n = 0; n < 100000; ++n) {
        const TableSample s = t.sample(kOnNode, u(rng), u(rng), u(rng));
        const int i = t.theta_i_cells().cell_of_sin(s.sin_theta_i),
                  j = t.phi_cells().cell_of(s.phi);
        // The cell boundaries are where the table says: sin of equally spaced θ.
        ASSERT_GE(double(s.sin_theta_i), std::sin(-kHalfPi + kPi * i / kThetaCells) - 1e-7);
        ASSERT_LE(double(s.sin_theta_i), std::sin(-kHalfPi + kPi * (i + 1) / kThetaCells) + 1e-7);
        ASSERT_GT(t.value(8, i, j), 0.0f) << "cell " << i << ", " << j;
        const TableSample q = m.sample(4, kOnNode, u(rng), u(rng), u(rng));
        const int qi = m.theta_i_cells().cell_of_sin(q.sin_theta_i);
        ASSERT_GT(m.value(8, 4, qi), 0.0f) << "cell " << qi;
    }
}

TEST(LongitudinalCells, LookupBySinThetaMatchesTheEdges) {
    for (int n : {1, 2, 7, 72, 1000, 4096}) {
        const LongitudinalCells c = unwrap(LongitudinalCells::create(n));
        for (int k = 0; k < n; ++k) {
            ASSERT_EQ(c.cell_of_sin(c.sin_edge(k)), k) << n;
            if (k > 0) {
                ASSERT_EQ(c.cell_of_sin(next_down(c.sin_edge(k))), k - 1) << n;
            }
            ASSERT_EQ(c.cell_of_sin(c.point_in_cell(k, 0.5f).sin_theta), k) << n;
            ASSERT_EQ(c.cell_of_sin(c.point_in_cell(k, kOneMinusEpsilon).sin_theta), k) << n;
            ASSERT_NEAR(double(c.sin_edge(k)), std::sin(-kHalfPi + kPi * k / n), 1e-7);
        }
        ASSERT_EQ(c.cell_of_sin(1.0f), n - 1);
        ASSERT_EQ(c.cell_of_sin(-1.0f), 0);
    }
}

TEST(LongitudinalCells, SamplesStayOffTheFiberAxis) {
    // On the axis (|sin θ| = 1) φ is undefined: a sample there would carry its φ in name only
    // and pdf() would read another. Rounding put ~10⁻⁴ of a polar cell's points there.
    for (int n : {1, 2, 90, 4096}) {
        const LongitudinalCells c = unwrap(LongitudinalCells::create(n));
        for (float t : {0.0f, 1e-9f, 1e-5f, kOneMinusEpsilon}) {
            for (int k : {0, n - 1}) {
                const LongitudinalCells::Point p = c.point_in_cell(k, t);
                EXPECT_LT(std::fabs(p.sin_theta), 1.0f) << n << " " << k << " " << t;
                EXPECT_GT(p.cos_theta, 0.0f) << n << " " << k << " " << t;
                EXPECT_EQ(c.cell_of_sin(p.sin_theta), k) << n << " " << k << " " << t;
            }
        }
    }
}

TEST(AzimuthTrig, MatchesCosAndSin) {
    const AzimuthTrig trig;
    for (int k = 0; k <= 100000; ++k) {
        const float phi = float(-kPi + kTwoPi * k / 100000);
        float c, s;
        trig(phi, c, s);
        ASSERT_NEAR(c, std::cos(double(phi)), 2e-7) << phi;
        ASSERT_NEAR(s, std::sin(double(phi)), 2e-7) << phi;
    }
}

// ---------------------------------------------------------------------------------------------
// Construction

TEST(SamplingTables, RebuiltFromAccessorsSamplesIdentically) {
    const DirectTable &a = direct_table();
    const DirectTable b = unwrap(
        DirectTable::create(a.theta_r_nodes(), a.theta_i_count(), a.phi_count(), a.values()));
    const MultipleTable &m = multiple_table();
    const MultipleTable n = unwrap(
        MultipleTable::create(m.theta_r_nodes(), m.n_h_values(), m.theta_i_count(), m.values()));
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), th(-1.6f, 1.6f);
    for (int k = 0; k < 1000; ++k) {
        const float theta_o = th(rng), u0 = u(rng), u1 = u(rng), u2 = u(rng);
        const TableSample x = a.sample(theta_o, u0, u1, u2), y = b.sample(theta_o, u0, u1, u2);
        ASSERT_EQ(x.sin_theta_i, y.sin_theta_i);
        ASSERT_EQ(x.phi, y.phi);
        ASSERT_EQ(x.pdf, y.pdf);
        const TableSample p = m.sample(2, theta_o, u0, u1, u2),
                          q = n.sample(2, theta_o, u0, u1, u2);
        ASSERT_EQ(p.sin_theta_i, q.sin_theta_i);
        ASSERT_EQ(p.pdf, q.pdf);
    }
}

std::string error_of(const Expected<DirectTable> &e) {
    return e.ok() ? "(accepted)" : e.error().message;
}
std::string error_of(const Expected<MultipleTable> &e) {
    return e.ok() ? "(accepted)" : e.error().message;
}

#define EXPECT_ERROR(expr, text) \
    EXPECT_NE(error_of(expr).find(text), std::string::npos) << "got: " << error_of(expr)

TEST(SamplingTables, RefusesInvalidTables) {
    const std::vector<float> nodes = {-1.0f, 0.0f, 1.0f};
    const std::vector<float> good(3 * 4 * 6, 1.0f);
    EXPECT_TRUE(DirectTable::create(nodes, 4, 6, good).ok());
    EXPECT_ERROR(DirectTable::create({}, 4, 6, good),
                 "theta_r node count must be an integer in [1, 1024]");
    EXPECT_ERROR(DirectTable::create({-1.0f, 1.0f, 0.0f}, 4, 6, good),
                 "theta_r_nodes must be strictly increasing");
    EXPECT_ERROR(DirectTable::create({0.0f, 0.0f, 1.0f}, 4, 6, good), "strictly increasing");
    EXPECT_ERROR(DirectTable::create({-1.0f, 0.0f, 1.6f}, 4, 6, good),
                 "theta_r_nodes[2] must be in");
    EXPECT_ERROR(DirectTable::create({-1.0f, std::nanf(""), 1.0f}, 4, 6, good), "theta_r_nodes[1]");
    EXPECT_ERROR(DirectTable::create(nodes, 0, 6, good),
                 "theta_i_count must be an integer in [1, 4096]");
    EXPECT_ERROR(DirectTable::create(nodes, 4, 5000, good), "phi_count");
    EXPECT_ERROR(DirectTable::create(nodes, 4, 5, good),
                 "values must hold node count × theta_i_count × phi_count = 60 entries (got 72)");
    std::vector<float> bad = good;
    bad[1 * 24 + 2 * 6 + 3] = -2.0f;
    EXPECT_ERROR(
        DirectTable::create(nodes, 4, 6, bad),
        "DirectTable: values[node 1, theta_i cell 2, phi cell 3] must be finite and >= 0 (got -2)");
    bad[1 * 24 + 2 * 6 + 3] = std::numeric_limits<float>::infinity();
    EXPECT_ERROR(DirectTable::create(nodes, 4, 6, bad), "(got inf)");
    // The memory bound is checked before the value count, so nothing is allocated for it.
    std::vector<float> many_nodes(1024);
    for (size_t k = 0; k < many_nodes.size(); ++k)
        many_nodes[k] = -1.5f + 3.0f * float(k) / 1024.0f;
    EXPECT_ERROR(DirectTable::create(many_nodes, 4096, 4096, {}), "would need");

    const std::vector<float> mgood(3 * 2 * 4, 1.0f);
    EXPECT_TRUE(MultipleTable::create(nodes, {1, 4}, 4, mgood).ok());
    EXPECT_ERROR(MultipleTable::create(nodes, {}, 4, mgood), "n_h value count");
    EXPECT_ERROR(MultipleTable::create(nodes, {4, 1}, 4, mgood),
                 "n_h_values must be strictly increasing");
    EXPECT_ERROR(MultipleTable::create(nodes, {0, 1}, 4, mgood),
                 "n_h_values[0] must be at least 1");
    EXPECT_ERROR(MultipleTable::create(nodes, {1, 4}, 5, mgood),
                 "values must hold node count × n_h count × theta_i_count = 30 entries (got 24)");
    std::vector<float> mbad = mgood;
    mbad[(2 * 2 + 1) * 4 + 3] = std::nanf("");
    EXPECT_ERROR(MultipleTable::create(nodes, {1, 4}, 4, mbad),
                 "values[node 2, n_h 4, theta_i cell 3] must be finite");
    EXPECT_ERROR(MultipleTable::create({0.5f}, {1}, 4, mgood), "entries");

}

TEST(SamplingTables, SingleNodeAndMissingStrands) {
    // One node: θ_r does not matter.
    const DirectTable one = unwrap(DirectTable::create({0.0f}, 8, 8, std::vector<float>(64, 2.0f)));
    EXPECT_NEAR(one.pdf(1.2f, 0.3f, -2.0f), float(kInvFourPi), 1e-6f);
    EXPECT_NEAR(one.sample(-0.4f, 0.3f, 0.6f, 0.9f).pdf, float(kInvFourPi), 1e-6f);
    EXPECT_EQ(multiple_table().sample(7, 0.2f, 0.4f, 0.5f, 0.1f).pdf,
              0.0f);  // no such strand index
    EXPECT_EQ(multiple_table().pdf(-1, 0.2f, 0.4f), 0.0f);
}

}  // namespace
}  // namespace hairis
