// Acceptance test of "the baked texture is the sampler": with a Chiang fiber, the TABLE
// strategy draws single scattering from the near part of the table file it is given, and
// from nothing else. Tables baked for a fiber get a different near part that is still valid
// for that fiber (cell masses and edge values reshaped, lobe integrals scaled, cone flags
// flipped, at half the θ_o nodes), are written as a file and read back; then
//  (a) the sampler the policy builds from that file is exact for what it holds (χ²);
//  (b) its density differs measurably from the original file's, and is the original's bit
//      for bit between two nodes the change left alone;
//  (c) renders of one scene with the original and the altered file agree in their mean
//      within the noise measured over several seeds, while their images differ: the render's
//      samples come from the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "chi2.h"
#include "core/frame.h"
#include "fiber/fiber_spec.h"
#include "render/render.h"
#include "sampler_at.h"
#include "sampling/strategy.h"
#include "tables/bake.h"
#include "tables/table_file.h"
#include "scene_fixtures.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;
using testing::SamplerAt;

constexpr int kLobes = 4;

// The nodes the change touches: r % 4 ∈ {0, 1}, so every fourth interval between nodes
// (r % 4 = 2) lies between two untouched nodes.
bool altered_node(int r) { return r % 4 < 2; }

// A near part for the same fiber that samples differently: at the altered nodes each lobe's
// cell masses and edge values (the density inside a cell) are reshaped and its integral (its
// selection weight) scaled; at every eighth node TT and TRT switch between their rows and the
// fiber's cone. Every value stays finite and positive where it was, so the tables stay valid
// and the sampler keeps the support of f.
NearFieldData altered(const NearFieldData &n) {
    static constexpr double kIntegralScale[kLobes] = {2.5, 0.6, 1.8, 0.4};
    NearFieldData a = n;
    const size_t cells = size_t(n.theta_i_cells);
    for (int r = 0; r < n.theta_o_nodes; ++r) {
        if (!altered_node(r)) continue;
        for (int p = 0; p < kLobes; ++p) {
            const size_t row = size_t(r) * kLobes + size_t(p);
            for (size_t k = 0; k < cells; ++k)
                a.mass[row * cells + k] =
                    float(double(n.mass[row * cells + k]) * (0.35 + 1.3 * std::fmod(0.618034 * double(k) + 0.25 * p, 1.0)));
            for (size_t k = 0; k <= cells; ++k)
                a.edge[row * (cells + 1) + k] = float(double(n.edge[row * (cells + 1) + k]) * (0.5 + 0.5 * double(k % 3)));
            a.integral[row] = float(double(n.integral[row]) * kIntegralScale[p]);
            if (r % 8 == 0 && (p == 1 || p == 2)) a.cone[row] = n.cone[row] ? 0 : 1;
        }
    }
    return a;
}

TableSet through_a_file(const TableSet &t) {
    const Expected<std::vector<unsigned char>> bytes = encode_table_exr(t);
    EXPECT_TRUE(bytes.ok()) << bytes.error().message;
    Expected<TableSet> back = decode_table_exr(bytes.value().data(), bytes.value().size());
    EXPECT_TRUE(back.ok()) << back.error().message;
    return std::move(back).value();
}

struct Fixture {
    std::shared_ptr<const ChiangFiber> fiber;
    TableSet baked;                 // the bake, in memory
    TableSet original, modified;    // read from files: the bake's, and the altered one's
    SamplingTables baked_tables, original_tables, modified_tables;
};

const Fixture &fixture() {
    static const Fixture f = [] {
        Fixture x;
        const FiberSpec spec = FiberSpec::preset("cycles-default").value();
        x.fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(to_chiang_params(spec.node).value()).value());
        BakeOptions options;
        options.theta_r_count = 15;
        options.theta_i_count = 32;
        options.phi_count = 32;
        x.baked = bake_tables(*x.fiber, spec.parameters().value(), options).value();
        x.original = through_a_file(x.baked);
        TableSet changed = x.baked;
        changed.near_field = std::make_shared<const NearFieldData>(altered(*x.baked.near_field));
        x.modified = through_a_file(changed);
        x.baked_tables = SamplingTables::from(x.baked).value();
        x.original_tables = SamplingTables::from(x.original).value();
        x.modified_tables = SamplingTables::from(x.modified).value();
        return x;
    }();
    return f;
}

// The policy's sampler for the fixture's fiber from `tables` (single scattering only: the
// renderer's default multiple_weight 0).
std::shared_ptr<const Sampler> table_sampler(const SamplingTables &tables) {
    StrategyInputs in;
    in.chiang = fixture().fiber;
    in.tables = &tables;
    in.multiple_weight = 0.0f;
    in.n_h = 2;
    Expected<std::shared_ptr<const Sampler>> s = make_sampler(StrategyKind::Table, in);
    EXPECT_TRUE(s.ok()) << s.error().message;
    return s.value();
}

Vec3 view_at(double theta_o_deg) { return direction_of(float(radians(theta_o_deg)), -float(kHalfPi)); }

TEST(BakedTextureIsTheSampler, TheFileCarriesTheChange) {
    const Fixture &f = fixture();
    ASSERT_TRUE(f.original.near_field && f.modified.near_field);
    const NearFieldData &o = *f.original.near_field, &m = *f.modified.near_field;
    const NearFieldData expected = altered(*f.baked.near_field);
    EXPECT_EQ(0, std::memcmp(m.mass.data(), expected.mass.data(), m.mass.size() * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(m.edge.data(), expected.edge.data(), m.edge.size() * sizeof(float)));
    EXPECT_EQ(m.integral, expected.integral);
    EXPECT_EQ(m.cone, expected.cone);
    int masses = 0, flags = 0;
    for (size_t i = 0; i < o.mass.size(); ++i) masses += o.mass[i] != m.mass[i];
    for (size_t i = 0; i < o.cone.size(); ++i) flags += o.cone[i] != m.cone[i];
    EXPECT_GT(masses, int(o.mass.size()) / 3);
    EXPECT_EQ(flags, 2 * ((o.theta_o_nodes + 7) / 8));
    // The far part and what the tables are for are the bake's.
    EXPECT_EQ(f.modified.direct, f.baked.direct);
    EXPECT_EQ(canonical_parameters(f.modified.parameters), canonical_parameters(f.baked.parameters));
}

// θ_o (degrees; nodes every 1.5°, node r at −90° + 1.5°·r): on altered node 60 (0°), between
// the altered nodes 60 and 61, between untouched node 63 and node 64 whose TT and TRT draw
// from the cone, on node 64, between nodes 35 and 36 (36: cone), and near grazing (nodes 1–2).
const double kThetaO[] = {0.0, 0.7, 5.5, 6.0, -36.75, -88.0};
const float kH[] = {0.35f, -0.8f};

TEST(BakedTextureIsTheSampler, TheAlteredFilesSamplerIsExact) {
    const auto sampler = table_sampler(fixture().modified_tables);
    Chi2Options options;
    options.test_count = int(std::size(kThetaO) * std::size(kH));
    const int cells = fixture().modified.near_field->theta_i_cells;
    for (int k = 0; k <= cells; ++k) options.theta_breaks.push_back(-kHalfPi + kPi * k / cells);
    for (const double theta_o : kThetaO)
        for (const float h : kH) {
            const SamplerAt at(*sampler, view_at(theta_o), h);
            const auto r = testing::chi2_sampler_test(at, options);
            EXPECT_TRUE(r.passed) << "theta_o " << theta_o << " h " << h << ": " << r.message;
            EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << "theta_o " << theta_o << " h " << h;
            EXPECT_EQ(r.failed_samples, 0);
            std::printf("chi2 theta_o %6.2f h %5.2f: p = %.4f (%s)\n", theta_o, double(h), r.p_value, r.message.c_str());
        }
}

// ∫ |p_a − p_b| dω over the sphere (midpoint rule in sin θ_i and φ, equal solid angles), and
// whether the two densities are equal bit for bit at every point.
struct Difference {
    double l1 = 0;
    bool identical = true;
};
Difference difference(const Sampler &a, const Sampler &b, double theta_o, float h) {
    const SamplerAt at_a(a, view_at(theta_o), h), at_b(b, view_at(theta_o), h);
    constexpr int kSin = 400, kPhi = 800;
    const double cell = (2.0 / kSin) * (kTwoPi / kPhi);
    Difference d;
    for (int i = 0; i < kSin; ++i)
        for (int j = 0; j < kPhi; ++j) {
            const double s = -1.0 + 2.0 * (i + 0.5) / kSin, phi = -kPi + kTwoPi * (j + 0.5) / kPhi;
            const Vec3 wi = direction_of(float(std::asin(s)), float(phi));
            const float pa = at_a.pdf(wi), pb = at_b.pdf(wi);
            d.l1 += std::fabs(double(pa) - double(pb)) * cell;
            d.identical = d.identical && std::memcmp(&pa, &pb, sizeof pa) == 0;
        }
    return d;
}

TEST(BakedTextureIsTheSampler, ItsDensityIsTheAlteredFilesNotTheBakes) {
    const auto original = table_sampler(fixture().original_tables);
    const auto modified = table_sampler(fixture().modified_tables);
    // Where the change applies, the densities differ by a sizeable fraction of their mass
    // (total variation = L1 / 2).
    for (const double theta_o : {0.0, 0.7, 5.5, -36.75})
        for (const float h : kH) {
            const Difference d = difference(*original, *modified, theta_o, h);
            std::printf("theta_o %6.2f h %5.2f: L1 distance of the densities %.4f\n", theta_o, double(h), d.l1);
            EXPECT_GT(d.l1, 0.1) << "theta_o " << theta_o << " h " << h;
            EXPECT_FALSE(d.identical);
        }
    // Between nodes 62 and 63, both untouched, the density is the original's bit for bit.
    for (const float h : kH) {
        const Difference d = difference(*original, *modified, 3.75, h);
        EXPECT_TRUE(d.identical) << "h " << h;
        EXPECT_EQ(d.l1, 0.0);
    }
    // The original file samples as the bake in memory does, bit for bit.
    const Difference same = difference(*table_sampler(fixture().baked_tables), *original, 0.7, 0.35f);
    EXPECT_TRUE(same.identical);
}

// ---- Renders ---------------------------------------------------------------------------------

constexpr int kWidth = 24, kHeight = 24;

// 160 straight hairs crossing the view at every in-plane angle and tilted by up to ±40° out of
// it (θ_o spreads over the nodes already at the camera's hits), under a sun and a sky.
Scene hair_scene(const std::shared_ptr<const Sampler> &sampler) {
    SceneDesc d;
    d.materials = {HairMaterial{HairShading::create(fixture().fiber, sampler).value()}};
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    HairCurves c;
    c.first.push_back(0);
    for (int i = 0; i < 160; ++i) {
        const Vec3 centre{0.6f * u(rng), 0.6f * u(rng), 0.1f * u(rng)};
        const float azimuth = float(kPi) * u(rng), tilt = 0.7f * u(rng);
        const Vec3 along{std::cos(azimuth) * std::cos(tilt), std::sin(azimuth) * std::cos(tilt), std::sin(tilt)};
        for (int k = 0; k < 4; ++k) {
            c.points.push_back(centre + along * (-1.0f + 2.0f * float(k) / 3.0f));
            c.radii.push_back(0.015f);
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    d.curves = {c};
    d.world = {Rgb(0.3f, 0.35f, 0.4f), 1.0f};
    testing::set_sun(d, safe_normalize(Vec3{0.4f, -0.3f, 1.0f}), 3.0f, float(radians(3.0)));
    CameraDesc camera;
    camera.camera_to_world = Mat4::translation({0, 0, 3});  // looks down −Z
    const float tan_half = 0.2f;
    camera.frame = {Vec3{tan_half, tan_half, -1}, Vec3{tan_half, -tan_half, -1}, Vec3{-tan_half, -tan_half, -1},
                    Vec3{-tan_half, tan_half, -1}};
    camera.width = kWidth;
    camera.height = kHeight;
    d.camera = camera;
    Expected<Scene> scene = Scene::build(std::move(d));
    EXPECT_TRUE(scene.ok()) << scene.error().message;
    return std::move(scene).value();
}

// Per pixel, the mean over rgb of an image.
std::vector<double> render_image(const Scene &scene, std::uint64_t seed, int samples) {
    RenderSettings s;
    s.samples = samples;
    s.seed = seed;
    std::vector<float> rgba(size_t(kWidth) * kHeight * 4);
    const Status st = render(scene, s, rgba.data(), {}, nullptr);
    EXPECT_FALSE(st) << st->message;
    std::vector<double> v(size_t(kWidth) * kHeight);
    for (size_t p = 0; p < v.size(); ++p) v[p] = (double(rgba[4 * p]) + rgba[4 * p + 1] + rgba[4 * p + 2]) / 3.0;
    return v;
}

// Per pixel, the mean of `seeds` images and the variance of that mean (from the spread of the
// images over the seeds).
struct PixelStats {
    std::vector<double> mean, variance_of_mean;
    std::vector<std::vector<double>> images;
};
PixelStats render_seeds(const Scene &scene, int seeds, int samples) {
    PixelStats st;
    const size_t n = size_t(kWidth) * kHeight;
    st.mean.assign(n, 0.0);
    st.variance_of_mean.assign(n, 0.0);
    for (int s = 0; s < seeds; ++s) st.images.push_back(render_image(scene, std::uint64_t(1000 + s), samples));
    for (size_t p = 0; p < n; ++p) {
        double sum = 0, sum2 = 0;
        for (const auto &image : st.images) sum += image[p];
        const double mean = sum / seeds;
        for (const auto &image : st.images) sum2 += (image[p] - mean) * (image[p] - mean);
        st.mean[p] = mean;
        st.variance_of_mean[p] = sum2 / (seeds - 1) / seeds;
    }
    return st;
}

TEST(BakedTextureIsTheSampler, RendersAgreeInTheMeanAndDifferInTheNoise) {
    constexpr int kSeeds = 16, kSamples = 32;
    const Scene original = hair_scene(table_sampler(fixture().original_tables));
    const Scene modified = hair_scene(table_sampler(fixture().modified_tables));
    const PixelStats o = render_seeds(original, kSeeds, kSamples), m = render_seeds(modified, kSeeds, kSamples);
    const size_t n = o.mean.size();

    // Pixels that see hair are noisy; the others (the sky alone) are exact in both.
    std::vector<size_t> hair;
    for (size_t p = 0; p < n; ++p) {
        if (o.variance_of_mean[p] > 0.0 || m.variance_of_mean[p] > 0.0) hair.push_back(p);
        else EXPECT_EQ(o.mean[p], m.mean[p]) << "pixel " << p;
    }
    ASSERT_GT(hair.size(), n / 2) << "the hair should cover most of the image";

    // The image means agree within 4 standard errors, the error from the per-pixel spreads
    // over the seeds (pixels and seeds are independent).
    double difference = 0, variance = 0, sum = 0;
    for (const size_t p : hair) {
        difference += m.mean[p] - o.mean[p];
        variance += m.variance_of_mean[p] + o.variance_of_mean[p];
        sum += o.mean[p];
    }
    difference /= double(hair.size());
    const double bound = 4.0 * std::sqrt(variance) / double(hair.size());
    std::printf("hair pixels %zu of %zu; image means: original %.6f, altered %.6f; difference %.6f, bound %.6f "
                "(4 standard errors)\n",
                hair.size(), n, sum / double(hair.size()), sum / double(hair.size()) + difference, difference, bound);
    EXPECT_LE(std::fabs(difference), bound);

    // The same in 16 blocks of 6 x 6 pixels, each at the Šidák-corrected two-sided 1% level
    // (|z| < 3.42 for 16 blocks).
    double worst = 0;
    for (int by = 0; by < kHeight / 6; ++by)
        for (int bx = 0; bx < kWidth / 6; ++bx) {
            double d = 0, v = 0;
            for (int y = by * 6; y < by * 6 + 6; ++y)
                for (int x = bx * 6; x < bx * 6 + 6; ++x) {
                    const size_t p = size_t(y) * kWidth + size_t(x);
                    d += m.mean[p] - o.mean[p];
                    v += m.variance_of_mean[p] + o.variance_of_mean[p];
                }
            if (v == 0.0) {
                EXPECT_EQ(d, 0.0);
                continue;
            }
            const double z = d / std::sqrt(v);
            worst = std::max(worst, std::fabs(z));
            EXPECT_LT(std::fabs(z), 3.42) << "block " << bx << "," << by;
        }
    std::printf("largest block |z| %.2f (bound 3.42)\n", worst);

    // With the same seed the images differ at almost every hair pixel, by the size of the
    // noise: the samples themselves come from the file. (The original file renders as the
    // bake in memory does, bit for bit, so the difference is the file's.)
    int differing = 0;
    double squared = 0, noise = 0;
    for (const size_t p : hair) {
        differing += o.images[0][p] != m.images[0][p];
        squared += (o.images[0][p] - m.images[0][p]) * (o.images[0][p] - m.images[0][p]);
        noise += kSeeds * (o.variance_of_mean[p] + m.variance_of_mean[p]);  // of one image's difference
    }
    std::printf("same seed: %d of %zu hair pixels differ; rms difference / rms noise of independent images %.3f\n",
                differing, hair.size(), std::sqrt(squared / noise));
    EXPECT_GT(differing, int(0.95 * double(hair.size())));
    EXPECT_GT(std::sqrt(squared / noise), 0.25);
    const Scene baked = hair_scene(table_sampler(fixture().baked_tables));
    EXPECT_EQ(render_image(baked, 1000, kSamples), o.images[0]);
}

}  // namespace
}  // namespace hairis
