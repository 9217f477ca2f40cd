#include "render/dual_scattering_integrator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "chi2.h"
#include "scene_fixtures.h"
#include "same_bits.h"
#include "core/quadrature.h"
#include "fiber/chiang.h"
#include "fiber/distributions.h"
#include "fiber/principled_hair.h"
#include "core/scratch.h"
#include "render/render.h"
#include "sampling/analytic_sampler.h"

namespace hairis {
namespace {

// ---- Fixtures -------------------------------------------------------------------------------

// A light (blonde-like) Chiang fiber, its dual-scattering averages and a multiple table made
// from them as the bake makes it (distributions.h's multiple_distribution per node and n_h).
struct Blonde {
    std::shared_ptr<const ChiangFiber> fiber;
    std::shared_ptr<const DualScattering> dual;
    std::shared_ptr<const MultipleTable> table;
    std::vector<int> n_h{1, 2, 4, 8, 16};
    int theta_i_count = 24;
};

std::shared_ptr<const MultipleTable> table_from(const DualScattering &dual, const std::vector<int> &n_h,
                                                int theta_r_count, int theta_i_count) {
    std::vector<float> nodes, values;
    for (int r = 0; r < theta_r_count; ++r) nodes.push_back(float(-kHalfPi + kPi * (r + 0.5) / theta_r_count));
    ThetaGridSpec spec;
    spec.theta_count = theta_i_count;
    for (float node : nodes)
        for (int n : n_h) {
            const Grid1D g = multiple_distribution(dual, node, n, spec).value();
            for (double v : g.values) values.push_back(float(v));
        }
    return std::make_shared<const MultipleTable>(MultipleTable::create(nodes, n_h, theta_i_count, values).value());
}

const Blonde &blonde() {
    static const Blonde b = [] {
        Blonde out;
        ChiangParams p;
        p.sigma_a = principled_hair::sigma_from_concentration(0.05, 0.05);  // melanin ≈ 0.1
        p.roughness = 0.3f;
        p.radial_roughness = 0.3f;
        out.fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(p).value());
        out.dual = std::make_shared<const DualScattering>(DualScattering::create(*out.fiber, {}).value());
        out.table = table_from(*out.dual, out.n_h, 12, out.theta_i_count);
        return out;
    }();
    return b;
}

HairMaterial dual_hair(const Blonde &b, std::shared_ptr<const MultipleTable> table = nullptr) {
    HairMaterial m{HairShading::create(b.fiber, std::make_shared<const AnalyticSampler>(b.fiber)).value()};
    m.dual = b.dual;
    m.multiple = table ? std::move(table) : b.table;
    return m;
}

// Straight hairs along +X (from x = −half to half, 4 points each) at the given (y, z).
HairCurves straight_hairs(const std::vector<Vec3> &centres, const std::vector<float> &radii, float half = 1.5f) {
    HairCurves c;
    c.first.push_back(0);
    for (std::size_t i = 0; i < centres.size(); ++i) {
        for (int k = 0; k < 4; ++k) {
            c.points.push_back({-half + 2.0f * half * float(k) / 3.0f, centres[i].y, centres[i].z});
            c.radii.push_back(radii[i]);
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    return c;
}

TriangleMesh quad_at(float half, float z, std::uint32_t material) {
    TriangleMesh m;
    m.positions = {{-half, -half, z}, {half, -half, z}, {half, half, z}, {-half, half, z}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.materials = {material};
    return m;
}

using testing::ortho_down;

Scene build(SceneDesc d) {
    auto s = Scene::build(std::move(d));
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    return std::move(s).value();
}

// The paper's unbounded hair volume and its dual scattering at the first hair hit (no exact
// bounces), whose closed forms most tests here check.
RenderSettings dual_settings(int max_bounces = 0, DualHairVolume volume = DualHairVolume::Unbounded) {
    RenderSettings s;
    s.integrator = int(Integrator::DualScattering);
    s.dual_exact_bounces = 0;
    s.dual_hair_volume = int(volume);
    s.dual_bounce_limit = int(DualBounceLimit::None);  // every order, as the paper's closed forms
    s.max_bounces = max_bounces;
    s.film_transparent = true;
    s.threads = 1;
    return s;
}

// ---- Strand crossings -------------------------------------------------------------------------

TEST(TraceThroughHair, ReportsEveryStrandCrossedOnceInOrder) {
    // Five hairs stacked under each other at z = −1, −2, ..., −5 (and one beside them that the
    // ray misses); the ray comes down the z axis at x = 0.3.
    const int k = 5;
    std::vector<Vec3> centres;
    std::vector<float> radii;
    for (int j = 1; j <= k; ++j) {
        centres.push_back({0, 0, -float(j)});
        radii.push_back(0.05f);
    }
    centres.push_back({0, 0.5f, -2.5f});
    radii.push_back(0.05f);
    SceneDesc d;
    d.materials = {DiffuseMaterial{}, dual_hair(blonde())};
    d.curves = {straight_hairs(centres, radii)};
    d.curves[0].material = 1;
    d.camera = ortho_down(1, 1, 4, 4);
    const Scene scene = build(std::move(d));
    std::vector<StrandCrossing> strands;
    const auto mesh = scene.trace_through_hair({0.3f, 0, 1}, {0, 0, -1}, 0.0f, INFINITY, {}, {}, strands);
    EXPECT_FALSE(mesh.has_value());
    ASSERT_EQ(strands.size(), std::size_t(k));
    for (int j = 0; j < k; ++j) {
        // The top of the tube of hair j + 1: t = 1 + (j + 1) − r.
        EXPECT_NEAR(strands[std::size_t(j)].t, 2.0f + float(j) - 0.05f, 1e-3f) << j;
        EXPECT_NEAR(std::fabs(strands[std::size_t(j)].tangent.x), 1.0f, 1e-5f);
        EXPECT_NEAR(strands[std::size_t(j)].radius, 0.05f, 1e-5f);
        EXPECT_EQ(strands[std::size_t(j)].material, 1u);
    }
    // Up to t = 3.5 only the first two.
    scene.trace_through_hair({0.3f, 0, 1}, {0, 0, -1}, 0.0f, 3.5f, {}, {}, strands);
    EXPECT_EQ(strands.size(), 2u);
    // Skipping the first hair's curve (a ray leaving it).
    const PrimRef first_curve{strands[0].segment.geometry, 0};
    scene.trace_through_hair({0.3f, 0, 1}, {0, 0, -1}, 0.0f, INFINITY, first_curve, {}, strands);
    EXPECT_EQ(strands.size(), std::size_t(k - 1));
}

TEST(TraceThroughHair, AJointOfTwoSegmentsIsOneCrossing) {
    // Points at x = −1.5, −0.5, 0.5, 1.5: the rays go through the joints at x = ±0.5, straight
    // down and obliquely, and through the middle of a segment.
    SceneDesc d;
    d.materials = {dual_hair(blonde())};
    d.curves = {straight_hairs({{0, 0, 0}}, {0.08f})};
    d.camera = ortho_down(1, 1, 4, 4);
    const Scene scene = build(std::move(d));
    std::vector<StrandCrossing> strands;
    for (float x : {-0.5f, 0.5f, 0.0f, -0.5f + 1e-3f}) {
        for (Vec3 dir : {Vec3{0, 0, -1}, safe_normalize(Vec3{0.7f, 0.2f, -1}), safe_normalize(Vec3{-0.1f, 0.9f, -0.3f})}) {
            const Vec3 origin = Vec3{x, 0, 0} - dir * 2.0f;
            scene.trace_through_hair(origin, dir, 0.0f, INFINITY, {}, {}, strands);
            EXPECT_EQ(strands.size(), 1u) << "x " << x << " dir " << dir.x << "," << dir.y << "," << dir.z;
        }
    }
}

TEST(TraceThroughHair, MeshesStopTheRayAndHairBehindThemIsNotReported) {
    SceneDesc d;
    d.materials = {DiffuseMaterial{}, dual_hair(blonde())};
    d.curves = {straight_hairs({{0, 0, -1}, {0, 0, -2}, {0, 0, -3}}, {0.05f, 0.05f, 0.05f})};
    d.curves[0].material = 1;
    d.meshes = {quad_at(2.0f, -2.5f, 0)};
    d.camera = ortho_down(1, 1, 4, 4);
    const Scene scene = build(std::move(d));
    std::vector<StrandCrossing> strands;
    const auto mesh = scene.trace_through_hair({0.2f, 0, 1}, {0, 0, -1}, 0.0f, INFINITY, {}, {}, strands);
    ASSERT_TRUE(mesh.has_value());
    EXPECT_NEAR(mesh->t, 3.5f, 1e-4f);
    EXPECT_EQ(strands.size(), 2u);
    // The same query's occlusion agrees with Scene::occluded for the mesh alone.
    EXPECT_TRUE(scene.occluded({0.2f, 0, -2.2f}, {0, 0, -1}, 0.0f, INFINITY));
}

// ---- Forward scattering and the multiple term ----------------------------------------------

StrandCrossing crossing_with_tangent(Vec3 tangent) {
    StrandCrossing c;
    c.tangent = safe_normalize(tangent);
    c.material = 99;  // not a material of the scene: the fallback's averages apply
    return c;
}

// T_f of k strands crossed at inclination θ: d_f (ā_f + sin²θ ā_b)^k, from the averages.
Rgb fixed_count_transmittance(const DualScattering &dual, double theta, int k) {
    const Rgb a_f = dual.forward_attenuation(theta), a_b = dual.backward_attenuation(theta);
    const double s2 = std::sin(theta) * std::sin(theta), d_f = dual.params().d_f;
    auto channel = [&](int ch) { return float(d_f * std::pow(double(a_f[ch]) + s2 * double(a_b[ch]), k)); };
    return {channel(0), channel(1), channel(2)};
}

// One blonde strand under an orthographic camera: the scene that gathers forward scattering
// along strands the tests describe themselves.
Scene one_blonde_strand() {
    SceneDesc d;
    d.materials = {dual_hair(blonde())};
    d.curves = {straight_hairs({{0, 0, 0}}, {0.05f})};
    d.camera = ortho_down(1, 1, 2, 2);
    return build(std::move(d));
}

TEST(DualScatteringIntegrator, StrandsAtOneInclinationGiveTheFixedCountForm) {
    // k strands crossed at the shading fiber's own inclination: T_f = d_f (ā_f + sin²θ ā_b)^k
    // and σ_f² = k β̄_f² (forward_spread_variance), and the multiple term is scattered_f_cos of
    // them; with a(θ) = ā_f (θ = 0) it is the paper's multiple_f_cos.
    const Blonde &b = blonde();
    const Scene scene = one_blonde_strand();
    for (double theta : {-0.9, -0.2, 0.0, 0.35, 1.1}) {
        const Vec3 dir{float(std::sin(theta)), float(std::cos(theta)), 0.0f};
        for (int k : {1, 2, 3, 7, 16}) {
            const std::vector<StrandCrossing> strands(std::size_t(k), crossing_with_tangent({1, 0, 0}));
            const ForwardScattering f = gather_forward_scattering(scene, strands.data(), strands.size(), dir, *b.dual);
            EXPECT_EQ(f.strands, k);
            const Rgb t_f = fixed_count_transmittance(*b.dual, theta, k);
            const Rgb s_f = b.dual->forward_spread_variance(theta, k);
            for (int ch = 0; ch < 3; ++ch) {
                EXPECT_NEAR(b.dual->params().d_f * f.attenuation[ch], t_f[ch], 1e-5 * t_f[ch] + 1e-12);
                EXPECT_NEAR(f.spread_variance[ch], s_f[ch], 1e-5 * s_f[ch]);
            }
            for (double theta_o : {-0.5, 0.0, 0.8}) {
                const Rgb got = dual_multiple_f_cos(*b.dual, float(theta), float(theta_o), f);
                const Rgb want = b.dual->scattered_f_cos(float(theta), float(theta_o), t_f, s_f);
                for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(got[ch], want[ch], 1e-4 * want[ch] + 1e-12);
                if (theta == 0.0) {
                    const Rgb paper = b.dual->multiple_f_cos(float(theta), float(theta_o), k);
                    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(got[ch], paper[ch], 1e-4 * paper[ch] + 1e-12);
                }
            }
        }
        const ForwardScattering none = gather_forward_scattering(scene, nullptr, 0, dir, *b.dual);
        const Rgb got = dual_multiple_f_cos(*b.dual, float(theta), 0.3f, none);
        const Rgb want = b.dual->multiple_f_cos(float(theta), 0.3f, 0);
        for (int ch = 0; ch < 3; ++ch) EXPECT_FLOAT_EQ(got[ch], want[ch]);
    }
}

TEST(DualScatteringIntegrator, EachStrandCountsAtItsOwnInclination) {
    // Strands of different orientations: T_f/d_f is the product of each one's
    // a = ā_f + sin²θ ā_b at the inclination θ of the light to it, σ_f² the sum of its β̄_f²,
    // and reversing a tangent flips the sign of that inclination.
    const Blonde &b = blonde();
    const Scene scene = one_blonde_strand();
    const Vec3 dir = safe_normalize(Vec3{0.3f, -0.5f, 0.8f});
    const std::vector<Vec3> tangents{{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0.2f, 0.9f, 0.4f}, {0, 0, -1}};
    std::vector<StrandCrossing> strands;
    double attenuation[3] = {1, 1, 1}, spread[3] = {0, 0, 0};
    for (Vec3 t : tangents) {
        strands.push_back(crossing_with_tangent(t));
        const double theta = std::asin(double(dot(dir, safe_normalize(t))));
        const Rgb a_f = b.dual->forward_attenuation(theta), a_b = b.dual->backward_attenuation(theta);
        const Rgb w = b.dual->forward_width(theta);
        for (int ch = 0; ch < 3; ++ch) {
            attenuation[ch] *= double(a_f[ch]) + std::sin(theta) * std::sin(theta) * double(a_b[ch]);
            spread[ch] += double(w[ch]) * w[ch];
        }
    }
    const ForwardScattering f = gather_forward_scattering(scene, strands.data(), strands.size(), dir, *b.dual);
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(f.attenuation[ch], attenuation[ch], 1e-5 * attenuation[ch]);
        EXPECT_NEAR(f.spread_variance[ch], spread[ch], 1e-5 * spread[ch]);
    }
    // The sign matters for a tilted fiber: ā_f(θ) ≠ ā_f(−θ).
    EXPECT_GT(std::fabs(b.dual->forward_attenuation(0.3).r - b.dual->forward_attenuation(-0.3).r), 1e-4f);
}

TEST(DualScatteringIntegrator, NearestStrandCountInLog2) {
    const MultipleTable &t = *blonde().table;
    const std::vector<std::pair<int, int>> cases{{0, 1}, {1, 1}, {2, 2}, {3, 4}, {4, 4}, {5, 4},
                                                 {6, 8}, {11, 8}, {12, 16}, {100, 16}};
    for (const auto &[strands, n_h] : cases)
        EXPECT_EQ(t.n_h_values()[std::size_t(nearest_strand_index(t, strands))], n_h) << strands;
}

// ---- The multiple-table sampling in world space (χ²) ------------------------------------------

TEST(DualScatteringIntegratorChi2, MultipleTableSamplesFollowTheirPdf) {
    const Blonde &b = blonde();
    const MultipleTable &table = *b.table;
    const Vec3 tangent = safe_normalize(Vec3{0.3f, -0.8f, 0.5f});
    const std::vector<Vec3> views{safe_normalize(Vec3{0.2f, 0.4f, 0.9f}), safe_normalize(Vec3{-0.7f, 0.1f, -0.2f})};
    const std::vector<int> strands{0, 4};
    const int tests = int(views.size() * strands.size());
    for (Vec3 wo : views) {
        const FiberFrame frame = FiberFrame::from_tangent_and_view(tangent, wo);
        const Vec3 wo_local = frame.to_local(wo);
        for (int strand : strands) {
            testing::Chi2Options o;
            o.test_count = tests;
            o.sin_theta_cells = 48;
            o.phi_cells = 24;
            for (int i = 1; i < table.theta_i_count(); ++i)
                o.theta_breaks.push_back(-kHalfPi + kPi * i / table.theta_i_count());
            // The harness's cells are in the fiber frame; samples and pdf go through the world.
            // A sample's own density and the pdf of its direction differ only where rounding
            // moves it across a cell edge.
            long long mismatches = 0;
            const testing::Chi2Result r = testing::chi2_direction_test(
                [&](testing::Sample3 u) -> std::optional<Vec3> {
                    const MultipleTableSample s = sample_multiple_table(table, strand, frame, wo_local, u.u0, u.u1, u.u2);
                    if (!(s.pdf > 0.0f)) return std::nullopt;
                    const float pdf = multiple_table_pdf(table, strand, frame, wo_local, s.wi);
                    if (std::fabs(pdf - s.pdf) > 1e-4f * s.pdf) ++mismatches;
                    return frame.to_local(s.wi);
                },
                [&](Vec3 l) { return double(multiple_table_pdf(table, strand, frame, wo_local, frame.to_world(l))); }, o);
            EXPECT_TRUE(r.passed) << "strand " << strand << ": " << r.message;
            EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3);
            EXPECT_LT(mismatches, 100) << "of " << o.sample_count;
        }
    }
}

// ---- Renders against closed forms and quadrature ---------------------------------------------

// A thin hair at z = 0 seen from above through a window that only it fills, k thicker hairs
// under it at z = −0.2j, and a delta sun below and along +X at θ_i = 0.4 from the hairs' normal
// plane, in a black world.
Scene sun_through_strands(int k, float strength) {
    std::vector<Vec3> centres{{0, 0, 0}};
    std::vector<float> radii{0.02f};
    for (int j = 1; j <= k; ++j) {
        centres.push_back({0, 0, -0.2f * float(j)});
        radii.push_back(0.06f);
    }
    SceneDesc d;
    d.materials = {dual_hair(blonde())};
    d.curves = {straight_hairs(centres, radii)};
    testing::set_sun(d, {float(std::sin(0.4)), 0.0f, -float(std::cos(0.4))}, strength);
    d.world = {Rgb(0.0f), 1.0f};
    d.camera = ortho_down(0.4f, 0.012f, 8, 2);
    return build(std::move(d));
}

TEST(DualScatteringRender, SunThroughKStrandsIsTheClosedForm) {
    // Every sample sees the top hair at θ_o = 0 with the sun behind k strands: its light is
    // E·T_f d_f (f_s^scatter + π d_b f_back^scatter) cos θ_i, the fixed-count form with
    // T_f = d_f a(0.4)^k (the strands are parallel to the shading fiber), whatever h and the
    // other samples do.
    const float strength = 2.0f;
    const DualScattering &dual = *blonde().dual;
    for (int k : {1, 3, 6}) {
        const Scene scene = sun_through_strands(k, strength);
        const Rgb want = dual.scattered_f_cos(0.4f, 0.0f, fixed_count_transmittance(dual, 0.4, k),
                                              dual.forward_spread_variance(0.4, k)) *
                         strength;
        for (int bounces : {0, 4}) {
            const RenderSettings s = dual_settings(bounces);
            for (int x = 0; x < 8; x += 3)
                for (std::uint64_t i = 0; i < 16; ++i) {
                    float alpha = 0;
                    const Rgb got = render_sample(scene, s, x, 1, i, &alpha);
                    ASSERT_EQ(alpha, 1.0f);
                    for (int ch = 0; ch < 3; ++ch)
                        EXPECT_NEAR(got[ch], want[ch], 2e-4 * want[ch]) << "k " << k << " ch " << ch;
                }
        }
        // The path tracer sees the sun blocked by hair: its single-scattering term is zero.
        RenderSettings path = dual_settings(0);
        path.integrator = int(Integrator::Path);
        EXPECT_EQ(render_sample(scene, path, 3, 1, 0).g, 0.0f);
    }
}

TEST(DualScatteringRender, TheBounceLimitKeepsTheOrdersThePathTracerReaches) {
    // sun_through_strands(k) with Max Bounces B: the sun's light crosses k strands (k events)
    // and a backscatter term through i strands behind adds 2i, so the vertex at depth 0 keeps
    // the global term for k <= B with Ā_b's series cut at (B − k)/2 strands behind, nothing for
    // k > B. Max Transmission Bounces limits alike.
    const float strength = 2.0f;
    const DualScattering &dual = *blonde().dual;
    for (int k : {1, 3, 6}) {
        const Scene scene = sun_through_strands(k, strength);
        for (int limit : {2, 5, 8}) {
            const Rgb t_f = fixed_count_transmittance(dual, 0.4, k);
            const Rgb s_f2 = dual.forward_spread_variance(0.4, k);
            const Rgb want = k > limit ? Rgb(0.0f) : dual.scattered_f_cos(0.4f, 0.0f, t_f, s_f2, (limit - k) / 2) * strength;
            for (const bool by_transmission : {false, true}) {
                RenderSettings s = dual_settings(by_transmission ? 12 : limit);
                if (by_transmission) s.max_transmission_bounces = limit;
                s.dual_bounce_limit = int(DualBounceLimit::Bounces);
                for (std::uint64_t i = 0; i < 8; ++i) {
                    const Rgb got = render_sample(scene, s, 3, 1, i);
                    for (int ch = 0; ch < 3; ++ch)
                        EXPECT_NEAR(got[ch], want[ch], 2e-4 * want[ch] + 1e-9)
                            << "k " << k << " limit " << limit << " transmission " << by_transmission << " ch " << ch;
                }
            }
        }
        // The cut moves the value: the series through 0 strands behind is not the unbounded one.
        const Rgb t_f = fixed_count_transmittance(dual, 0.4, k), s_f2 = dual.forward_spread_variance(0.4, k);
        const Rgb unbounded = dual.scattered_f_cos(0.4f, 0.0f, t_f, s_f2) * strength;
        const Rgb cut = dual.scattered_f_cos(0.4f, 0.0f, t_f, s_f2, 0) * strength;
        EXPECT_GT(unbounded.r, 1.01f * cut.r) << "k " << k;
    }
}

TEST(DualScatteringIntegrator, TheProbeCountsTheStrandsTowardsTheLight) {
    // The top hair of sun_through_strands(k), shaded directly: the n_h probe goes towards the
    // (only) lamp and crosses the k strands under it; the table's strand count is the nearest.
    // The probe's count is the independent reference's: the strands the scene was built with.
    for (int k : {0, 1, 3, 6}) {
        const Scene scene = sun_through_strands(k, 1.0f);
        const Vec3 origin{0.05f, 0.004f, 1.0f}, down{0, 0, -1};
        const std::optional<Hit> hit = scene.intersect(origin, down, 0.0f, INFINITY);
        ASSERT_TRUE(hit.has_value());
        const SurfacePoint sp = scene.surface_point(origin, down, *hit);
        ASSERT_TRUE(sp.is_curve);
        const HairMaterial &material = std::get<HairMaterial>(scene.materials()[sp.material]);
        DualVertex v;
        v.point = &sp;
        v.material = &material;
        v.wo = -down;
        v.frame = FiberFrame::from_tangent_and_view(sp.tangent, v.wo);
        ScratchBuffer scratch;
        const float h = std::clamp(dot(cross(sp.normal, v.frame.x), v.frame.z), -1.0f, 1.0f);
        const HairBsdf bsdf = material.shading.at({v.frame.to_local(v.wo), h}, scratch);
        v.bsdf = &bsdf;
        DualWork work;
        DualRandom u;
        u.table_u0 = u.table_u1 = u.table_u2 = 0.5f;
        const Rgb l = dual_scattering_light(scene, v, u, work);
        EXPECT_EQ(work.last_probe_strands, k);
        EXPECT_EQ(material.multiple->n_h_values()[std::size_t(work.last_strand_index)],
                  material.multiple->n_h_values()[std::size_t(nearest_strand_index(*material.multiple, k))]);
        // The sun's probe ray is the light sample's shadow ray: traced once (and the table's).
        EXPECT_EQ(work.rays, 2u);
        EXPECT_GT(l.r, 0.0f);
        // With r bounces left the probe stops after r + 1 strands: light past r does not count.
        for (int r : {0, 2, 5}) {
            v.bounces_left = r;
            DualWork limited;
            dual_scattering_light(scene, v, u, limited);
            EXPECT_EQ(limited.last_probe_strands, std::min(k, r + 1)) << k << " strands, r = " << r;
        }
    }
}

struct Estimate {
    double mean[3] = {0, 0, 0}, sigma[3] = {0, 0, 0};
    double reference[3] = {0, 0, 0};  ///< mean_difference: the second render's mean
};

// The mean and standard error of the single pixel's samples that hit hair.
Estimate hair_pixel(const Scene &scene, const RenderSettings &s, int n) {
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    int hits = 0;
    for (std::uint64_t i = 0; i < std::uint64_t(n); ++i) {
        float alpha = 0;
        const Rgb l = render_sample(scene, s, 0, 0, i, &alpha);
        if (alpha == 0.0f) continue;
        ++hits;
        for (int ch = 0; ch < 3; ++ch) {
            sum[ch] += l[ch];
            sum2[ch] += double(l[ch]) * l[ch];
        }
    }
    EXPECT_GT(hits, n / 2);
    Estimate e;
    for (int ch = 0; ch < 3; ++ch) {
        e.mean[ch] = sum[ch] / std::max(hits, 1);
        e.sigma[ch] = std::sqrt(std::max(0.0, sum2[ch] / std::max(hits, 1) - e.mean[ch] * e.mean[ch]) / std::max(hits, 1));
    }
    return e;
}

// Per camera sample of the pixel (0, 0), render(a, sa) − render(b, sb) with the same random
// numbers: its mean and standard error, over the samples whose first render hits something;
// `reference` is the mean of the second render over them.
Estimate mean_difference(const Scene &a, const RenderSettings &sa, const Scene &b, const RenderSettings &sb,
                         int n) {
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0}, second[3] = {0, 0, 0};
    int hits = 0;
    for (std::uint64_t i = 0; i < std::uint64_t(n); ++i) {
        float alpha = 0;
        const Rgb x = render_sample(a, sa, 0, 0, i, &alpha);
        if (alpha == 0.0f) continue;
        const Rgb y = render_sample(b, sb, 0, 0, i);
        ++hits;
        for (int ch = 0; ch < 3; ++ch) {
            const double v = double(x[ch]) - double(y[ch]);
            sum[ch] += v;
            sum2[ch] += v * v;
            second[ch] += y[ch];
        }
    }
    EXPECT_GT(hits, 0);
    Estimate e;
    const double k = std::max(hits, 1);
    for (int ch = 0; ch < 3; ++ch) {
        e.mean[ch] = sum[ch] / k;
        e.sigma[ch] = std::sqrt(std::max(0.0, sum2[ch] / k - e.mean[ch] * e.mean[ch]) / k);
        e.reference[ch] = second[ch] / k;
    }
    return e;
}

// Straight hairs of radius r over a white floor (albedo 0.8) at floor_z, lit by a sun straight
// above, seen straight down through a square window of half-width `window`.
constexpr Vec3 kSunAbove{0, 0, 1};
constexpr float kFloorAlbedo = 0.8f;
Scene sunlit_floor(const std::vector<Vec3> &centres, float r, float floor_z, float window, float strength,
                   bool floor) {
    SceneDesc d;
    d.materials = {dual_hair(blonde()), DiffuseMaterial{Rgb(kFloorAlbedo)}};
    d.curves = {straight_hairs(centres, std::vector<float>(centres.size(), r), 3.0f)};
    if (floor) d.meshes = {quad_at(1.0f, floor_z, 1)};
    testing::set_sun(d, kSunAbove, strength);
    d.camera = ortho_down(window, window, 1, 1);
    return build(std::move(d));
}

// The floor's light at the hair the camera sees, ∫ f_cos(ω) L_floor(ω) dω over the directions
// that reach the floor, estimated independently of the renderer: ω uniform on the sphere from
// camera-ray hits on the hair. f_cos(hit, θ_i, θ_o, ω, strands crossed to the floor) is the term
// under test; mean and standard error per channel.
template <typename FCos>
Estimate floor_light_by_uniform_directions(const Scene &scene, float strength, int m, unsigned seed,
                                           FCos f_cos) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    std::vector<StrandCrossing> strands;
    for (int i = 0; i < m; ++i) {
        const CameraRay cr = scene.camera().generate_ray(0, 0, uniform(rng), uniform(rng));
        const auto hit = scene.intersect(cr.origin, cr.direction, cr.tmin, cr.tmax);
        EXPECT_TRUE(hit.has_value());
        if (!hit) continue;
        const SurfacePoint sp = scene.surface_point(cr.origin, cr.direction, *hit);
        const Vec3 wo = -cr.direction;
        const FiberFrame frame = FiberFrame::from_tangent_and_view(sp.tangent, wo);
        const float z = 1.0f - 2.0f * uniform(rng), phi = float(kTwoPi) * uniform(rng);
        const float rho = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 w{rho * std::cos(phi), rho * std::sin(phi), z};
        const auto floor = scene.trace_through_hair(sp.spawn_point(w), w, 0.0f, INFINITY, sp.self, {}, strands);
        Rgb value;
        if (floor && floor->prim.geometry != PrimRef::kNone) {
            const SurfacePoint fp = scene.surface_point(sp.spawn_point(w), w, *floor);
            const bool lit = !scene.occluded(fp.spawn_point(kSunAbove), kSunAbove, 0.0f, INFINITY, fp.self);
            const float theta_i = std::asin(std::clamp(frame.to_local(w).x, -1.0f, 1.0f));
            const float theta_o = std::asin(std::clamp(frame.to_local(wo).x, -1.0f, 1.0f));
            const Rgb floor_radiance = Rgb(kFloorAlbedo * strength / float(kPi)) * (lit ? 1.0f : 0.0f);
            value = f_cos(sp, theta_i, theta_o, w, strands) * floor_radiance * float(4.0 * kPi);
        }
        for (int ch = 0; ch < 3; ++ch) {
            sum[ch] += value[ch];
            sum2[ch] += double(value[ch]) * value[ch];
        }
    }
    Estimate e;
    for (int ch = 0; ch < 3; ++ch) {
        e.mean[ch] = sum[ch] / m;
        e.sigma[ch] = std::sqrt(std::max(0.0, sum2[ch] / m - e.mean[ch] * e.mean[ch]) / m);
    }
    return e;
}

TEST(DualScatteringRender, ALayersMeshLightThroughStrandsIsTheGlobalTerm) {
    // A hair above a mat of touching strands above a sunlit white floor: every direction from
    // the hair to the floor crosses the mat. With Layer, the floor's light is the global term
    // M(n) of the strands crossed: the render with the floor less the render without it (the
    // same random numbers) against an estimate over uniform directions from the hair's hits.
    const float strength = 3.0f, r = 0.02f;
    std::vector<Vec3> centres{{0, 0, 0}};
    for (int k = -3; k <= 3; ++k) centres.push_back({0, float(k) * 2.0f * r, -0.05f});
    const Scene with = sunlit_floor(centres, r, -1.0f, 0.01f, strength, true);
    const Scene without = sunlit_floor(centres, r, -1.0f, 0.01f, strength, false);
    const RenderSettings s = dual_settings(1, DualHairVolume::Layer);
    const Estimate floor_light = mean_difference(with, s, without, s, 20000);
    const DualScattering &dual = *blonde().dual;
    std::vector<StrandCrossing> behind;
    const Estimate want = floor_light_by_uniform_directions(
        with, strength, 100000, 11,
        [&](const SurfacePoint &sp, float theta_i, float theta_o, Vec3 w, const std::vector<StrandCrossing> &strands) {
            EXPECT_FALSE(strands.empty()) << "the mat covers the floor";
            // The vertex's depth: the strands behind it away from the probe's light, the sun.
            with.trace_through_hair(sp.spawn_point(-kSunAbove), -kSunAbove, 0.0f, INFINITY, sp.self, {}, behind);
            const ForwardScattering forward = gather_forward_scattering(with, strands.data(), strands.size(), w, dual);
            return dual_multiple_f_cos(dual, theta_i, theta_o, forward, int(behind.size()));
        });
    for (int ch = 0; ch < 3; ++ch) {
        ASSERT_GT(want.mean[ch], 0.0);
        EXPECT_NEAR(floor_light.mean[ch], want.mean[ch],
                    5.0 * std::hypot(floor_light.sigma[ch], want.sigma[ch])) << "ch " << ch;
    }
}

TEST(DualScatteringRender, ALayersUnoccludedMeshLightAlsoCarriesTheLocalBackscatter) {
    // A hair over a sunlit white floor with nothing between them, under a mat of strands with a
    // gap the camera looks through. The floor's light reaches the hair as a lamp's would:
    // F = f_s + d_b f_back^direct, Ā_b cut at the mat's strands behind the hair along the
    // light's travel (up). One bounce (camera → hair → floor → sun). The floor's light in dual
    // scattering less the path tracer's (each the render with the floor less the render
    // without it, same random numbers) is the local term alone, against an estimate over
    // uniform directions from the hair's hits.
    const float strength = 3.0f, r = 0.02f;
    std::vector<Vec3> centres{{0, 0, 0}};
    for (int k = 1; k <= 4; ++k) {
        centres.push_back({0, float(k) * 2.0f * r, 0.05f});
        centres.push_back({0, -float(k) * 2.0f * r, 0.05f});
    }
    const Scene with = sunlit_floor(centres, r, -0.3f, 0.005f, strength, true);
    const Scene without = sunlit_floor(centres, r, -0.3f, 0.005f, strength, false);
    RenderSettings path = dual_settings(1, DualHairVolume::Layer);
    path.integrator = int(Integrator::Path);
    const RenderSettings dual = dual_settings(1, DualHairVolume::Layer);
    const int n = 40000, m = 100000;
    const Estimate dual_floor = mean_difference(with, dual, without, dual, n);
    const Estimate path_floor = mean_difference(with, path, without, path, n);
    const DualScattering &averages = *blonde().dual;
    std::vector<StrandCrossing> behind;
    int cut = 0;
    const Estimate want = floor_light_by_uniform_directions(
        with, strength, m, 12,
        [&](const SurfacePoint &sp, float theta_i, float theta_o, Vec3 w, const std::vector<StrandCrossing> &strands) {
            EXPECT_NEAR(sp.position.z, 0.0f, 1.01f * r) << "the camera sees the lower hair through the gap";
            EXPECT_TRUE(strands.empty()) << "nothing lies between the hair and the floor";
            with.trace_through_hair(sp.spawn_point(-w), -w, 0.0f, INFINITY, sp.self, {}, behind);
            cut += behind.empty() ? 0 : 1;
            return averages.local_f_cos(theta_i, theta_o, int(behind.size()));
        });
    EXPECT_GT(cut, m / 10) << "the mat lies behind the hair for part of the floor's light";
    for (int ch = 0; ch < 3; ++ch) {
        const double got = dual_floor.mean[ch] - path_floor.mean[ch];
        const double sigma = std::sqrt(dual_floor.sigma[ch] * dual_floor.sigma[ch] +
                                       path_floor.sigma[ch] * path_floor.sigma[ch] + want.sigma[ch] * want.sigma[ch]);
        ASSERT_GT(want.mean[ch], 0.0);
        EXPECT_NEAR(got, want.mean[ch], 5.0 * sigma) << "ch " << ch;
        EXPECT_GT(want.mean[ch], 8.0 * sigma) << "the test tells the term from none, ch " << ch;
    }
}

TEST(DualScatteringRender, DirectlyLitHairIsSingleScatteringPlusLocalBackscatter) {
    // No strand under the hair: F = f_s + d_b f_back^direct. Over the hair's width (h uniform,
    // samples that miss it left out) f_s averages to the far field f_cos.
    const float strength = 2.0f;
    std::vector<Vec3> centres{{0, 0, 0}};
    SceneDesc d;
    d.materials = {dual_hair(blonde())};
    d.curves = {straight_hairs(centres, {0.02f})};
    testing::set_sun(d, {float(std::sin(0.4)), 0.0f, -float(std::cos(0.4))}, strength);
    d.camera = ortho_down(0.4f, 0.03f, 1, 1);
    const Scene scene = build(std::move(d));
    // Fiber frame at the hit: x = +X; ω_o = +Z; ω_i = to_sun.
    const FiberFrame frame = FiberFrame::from_tangent_and_view({1, 0, 0}, {0, 0, 1});
    const Vec3 wi = frame.to_local({float(std::sin(0.4)), 0.0f, -float(std::cos(0.4))});
    const Vec3 wo = frame.to_local({0, 0, 1});
    const Rgb want = (blonde().fiber->f_cos(wi, wo) + blonde().dual->local_f_cos(0.4f, 0.0f)) * strength;
    const Estimate e = hair_pixel(scene, dual_settings(0), 40000);
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(e.mean[ch], want[ch], 5.0 * e.sigma[ch] + 1e-4 * want[ch]) << "ch " << ch;
}

// A hair seen from above, lit directly by a sun along (0, sin a, cos a), a = 0.6, with three
// strands behind it along the light's way on (out of the camera's window).
Scene sun_with_three_strands_behind(float strength) {
    const float a = 0.6f, step = 0.1f;
    std::vector<Vec3> centres{{0, 0, 0}};
    for (int k = 1; k <= 3; ++k) centres.push_back({0, -float(k) * step * std::tan(a), -float(k) * step});
    SceneDesc d;
    d.materials = {dual_hair(blonde())};
    d.curves = {straight_hairs(centres, std::vector<float>(centres.size(), 0.02f))};
    testing::set_sun(d, {0.0f, std::sin(a), std::cos(a)}, strength);
    d.camera = ortho_down(0.4f, 0.03f, 1, 1);
    return build(std::move(d));
}

// f_s·cos θ_i of sun_with_three_strands_behind's light at the hair, seen from above.
Rgb sun_with_three_strands_behind_f_s() {
    const float a = 0.6f;
    const FiberFrame frame = FiberFrame::from_tangent_and_view({1, 0, 0}, {0, 0, 1});
    return blonde().fiber->f_cos(frame.to_local({0.0f, std::sin(a), std::cos(a)}), frame.to_local({0, 0, 1}));
}

TEST(DualScatteringRender, ALayerCutsTheLocalBackscatterAtTheStrandsBehind) {
    // The sun lights the top hair directly; three strands lie behind it along the light's way
    // on. Layer: F = f_s + d_b f_back^direct with Ā_b cut at 3 strands; Unbounded: the paper's
    // series.
    const float strength = 2.0f;
    const Scene scene = sun_with_three_strands_behind(strength);
    const Rgb f_s = sun_with_three_strands_behind_f_s();
    const Rgb layer = (f_s + blonde().dual->local_f_cos(0.0f, 0.0f, 3)) * strength;
    const Rgb unbounded = (f_s + blonde().dual->local_f_cos(0.0f, 0.0f)) * strength;
    const Estimate cut = hair_pixel(scene, dual_settings(0, DualHairVolume::Layer), 40000);
    const Estimate paper = hair_pixel(scene, dual_settings(0, DualHairVolume::Unbounded), 40000);
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(cut.mean[ch], layer[ch], 5.0 * cut.sigma[ch] + 1e-4 * layer[ch]) << "ch " << ch;
        EXPECT_NEAR(paper.mean[ch], unbounded[ch], 5.0 * paper.sigma[ch] + 1e-4 * unbounded[ch]) << "ch " << ch;
    }
    EXPECT_GT(unbounded.r - layer.r, 10.0f * float(cut.sigma[0])) << "the test tells the two apart";
}

TEST(DualScatteringRender, ABounceLimitCutsTheLayersBackscatterFurther) {
    // sun_with_three_strands_behind with the Bounce Limit: at depth 0 with Max Bounces B the
    // series through i strands behind cost 2i, so Ā_b is cut at min(3, B/2) strands.
    const float strength = 2.0f;
    const Scene scene = sun_with_three_strands_behind(strength);
    const Rgb f_s = sun_with_three_strands_behind_f_s();
    for (const int bounces : {0, 2, 4, 8}) {
        RenderSettings s = dual_settings(bounces, DualHairVolume::Layer);
        s.dual_bounce_limit = int(DualBounceLimit::Bounces);
        const Rgb want = (f_s + blonde().dual->local_f_cos(0.0f, 0.0f, std::min(3, bounces / 2))) * strength;
        const Estimate e = hair_pixel(scene, s, 20000);
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(e.mean[ch], want[ch], 5.0 * e.sigma[ch] + 1e-4 * want[ch]) << "bounces " << bounces << " ch " << ch;
        // The next deeper cut lies outside that tolerance where it differs (the test tells them apart).
        if (bounces < 4) {
            const Rgb deeper = (f_s + blonde().dual->local_f_cos(0.0f, 0.0f, bounces / 2 + 1)) * strength;
            EXPECT_GT(deeper.r - want.r, 8.0f * float(e.sigma[0]) + 1e-4f * want.r) << "bounces " << bounces;
        }
    }
}

// The same sample's radiance minus the path tracer's, over n samples of pixel (0, 0): at depth
// 0 both draw the same light sample and continuation with the same numbers, so the difference
// is the multiple-scattering term M alone.
// The multiple-scattering part of the unbounded dual estimate: dual − path, one bounce.
Estimate multiple_part(const Scene &scene, int n) {
    RenderSettings path = dual_settings(0);
    path.integrator = int(Integrator::Path);
    return mean_difference(scene, dual_settings(0), scene, path, n);
}

// A rectangular area light of size_x × size_y centred at `centre`, facing down, of `power` W.
AreaLight rectangle_light(Vec3 centre, float size_x, float size_y, float power) {
    AreaLight a;
    a.light_to_world = Mat4::translation(centre);
    a.shape = AreaShape::Rectangle;
    a.size_x = size_x;
    a.size_y = size_y;
    a.power = power;
    return a;
}

// One hair at z = 0 seen straight down (θ_o = 0) through a 2 cm window.
SceneDesc single_hair() {
    SceneDesc d;
    d.materials = {dual_hair(blonde())};
    d.curves = {straight_hairs({{0, 0, 0}}, {0.02f})};
    d.camera = ortho_down(0.01f, 0.01f, 1, 1);
    return d;
}

TEST(DualScatteringRender, ConstantWorldMultipleScatteringMatchesQuadrature) {
    // A constant world of radiance L is not light-sampled: M comes from the multiple table
    // alone and must integrate to L·2π ∫ local_f_cos(θ_i, 0) cos θ_i dθ_i (nothing is crossed).
    SceneDesc d = single_hair();
    d.world = {Rgb(1.0f, 0.8f, 0.5f), 1.5f};
    const Scene scene = build(std::move(d));
    const QuadratureRule q = QuadratureRule::composite(-kHalfPi, kHalfPi, 64, 8);
    double want[3] = {0, 0, 0};
    for (std::size_t i = 0; i < q.x.size(); ++i) {
        const Rgb m = blonde().dual->local_f_cos(float(q.x[i]), 0.0f);
        for (int ch = 0; ch < 3; ++ch) want[ch] += kTwoPi * q.w[i] * std::cos(q.x[i]) * m[ch];
    }
    const Rgb world = Rgb(1.0f, 0.8f, 0.5f) * 1.5f;
    const Estimate e = multiple_part(scene, 20000);
    for (int ch = 0; ch < 3; ++ch) {
        ASSERT_GT(want[ch], 0.0);
        EXPECT_NEAR(e.mean[ch], want[ch] * world[ch], 5.0 * e.sigma[ch] + 1e-4 * want[ch]) << "ch " << ch;
    }
}

TEST(DualScatteringRender, ALayerCutsEachSamplesBackscatterAlongItsOwnLight) {
    // A constant world over a hair lying on a sheet of parallel strands (two rows of seven,
    // below it). Light from above finds the strands its travel crosses behind the hair; light
    // from below crosses them first and finds none behind. M must integrate each direction's
    // term at its own depth, ∫ M(ω; forward(ω), depth(−ω)) L dω: by quadrature over the
    // sphere, with the crossings in closed form (the strands are parallel to the hair). One
    // depth for all the light, from a uniform probe, gives another value.
    const float r = 0.02f;
    std::vector<Vec3> centres{{0, 0, 0}};
    for (int row = 1; row <= 2; ++row)
        for (int j = -3; j <= 3; ++j) centres.push_back({0, 0.05f * float(j), -0.06f * float(row)});
    SceneDesc d;
    d.materials = {dual_hair(blonde())};
    d.curves = {straight_hairs(centres, std::vector<float>(centres.size(), r))};
    const float radiance = 1.3f;
    d.world = {Rgb(1.0f), radiance};
    d.camera = ortho_down(0.001f, 0.001f, 1, 1);  // the top of the hair, (0, 0, r)
    const Scene scene = build(std::move(d));
    const DualScattering &dual = *blonde().dual;
    // The strands a ray from (0, 0, r) along (·, dy, dz) crosses: those ahead of it whose axis
    // lies within r of it (not the hair itself).
    auto crossed = [&](double dy, double dz) {
        const double len = std::sqrt(dy * dy + dz * dz);
        int n = 0;
        for (std::size_t k = 1; k < centres.size(); ++k) {
            const double py = centres[k].y, pz = centres[k].z - r;  // the axis from the origin
            const double along = (py * dy + pz * dz) / len, off = std::fabs(py * dz - pz * dy) / len;
            n += along > 0 && off < r;
        }
        return n;
    };
    // M·cos θ_i of light from ω at the given depth behind the hair (θ_o = 0).
    auto term = [&](double u, double y, double z, int depth) {
        const float theta_i = float(std::asin(u));
        ForwardScattering forward;
        forward.strands = crossed(y, z);
        for (int k = 0; k < forward.strands; ++k) {
            forward.attenuation *= dual.crossing_attenuation(theta_i);
            forward.spread_variance += dual.forward_spread_variance(theta_i, 1);
        }
        return dual_multiple_f_cos(dual, theta_i, 0.0f, forward, depth);
    };
    const QuadratureRule q = QuadratureRule::composite(-1.0, 1.0, 16, 8);
    const int phis = 2048, most = int(centres.size());
    double want[3] = {0, 0, 0};
    std::vector<std::array<double, 3>> single(std::size_t(most), {0, 0, 0});
    std::vector<double> share(std::size_t(most), 0.0);
    for (std::size_t i = 0; i < q.x.size(); ++i)
        for (int j = 0; j < phis; ++j) {
            const double u = q.x[i], c = std::sqrt(1.0 - u * u), phi = kTwoPi * (j + 0.5) / phis;
            const double y = c * std::cos(phi), z = c * std::sin(phi), w = q.w[i] * kTwoPi / phis;
            const int behind = crossed(-y, -z);  // along the light's travel, −ω
            const Rgb m = term(u, y, z, behind);
            for (int ch = 0; ch < 3; ++ch) want[ch] += w * m[ch] * radiance;
            share[std::size_t(behind)] += w / (4.0 * kPi);  // a uniform probe's chance of `behind`
            if (i % 4 == 0 && j % 4 == 0)  // the probe's alternative on a coarser grid
                for (int k = 0; k < most; ++k) {
                    const Rgb mk = term(u, y, z, k);
                    for (int ch = 0; ch < 3; ++ch) single[std::size_t(k)][ch] += 16.0 * w * mk[ch] * radiance;
                }
        }
    RenderSettings path = dual_settings(0, DualHairVolume::Layer);
    path.integrator = int(Integrator::Path);
    const Estimate e = mean_difference(scene, dual_settings(0, DualHairVolume::Layer), scene, path, 40000);
    for (int ch = 0; ch < 3; ++ch) {
        double probe_depth = 0;
        for (int k = 0; k < most; ++k) probe_depth += share[std::size_t(k)] * single[std::size_t(k)][ch];
        ASSERT_GT(want[ch], 0.0);
        EXPECT_NEAR(e.mean[ch], want[ch], 5.0 * e.sigma[ch] + 3e-3 * want[ch]) << "ch " << ch;
        if (ch == 0) {
            std::printf("per-sample depth %.5f, one probe's depth %.5f, estimate %.5f ± %.5f\n", want[ch],
                        probe_depth, e.mean[ch], e.sigma[ch]);
            EXPECT_GT(std::fabs(want[ch] - probe_depth), 8.0 * e.sigma[ch]) << "the test tells the two apart";
        }
    }
}

TEST(DualScatteringRender, AreaLightMultipleScatteringMisMatchesQuadrature) {
    // A 6 m × 6 m area light 1 m above the hair, facing down, radiance L: light sampling and
    // table sampling of M, weighted by the power heuristic, integrate to
    //   ∫_light local_f_cos(θ_i(ω), 0) L dω = ∫∫ local_f_cos L h / d³ dx dy,
    // computed by Gauss–Legendre over the light's area.
    SceneDesc d = single_hair();
    const float radiance = 1.7f;
    d.area_lights = {rectangle_light({0, 0, 1}, 6.0f, 6.0f, radiance * 4.0f * 36.0f)};  // 3.4: L = P/(4·area)
    const Scene scene = build(std::move(d));
    const QuadratureRule q = QuadratureRule::composite(-3.0, 3.0, 48, 8);
    double want[3] = {0, 0, 0};
    const FiberFrame frame = FiberFrame::from_tangent_and_view({1, 0, 0}, {0, 0, 1});
    for (std::size_t i = 0; i < q.x.size(); ++i)
        for (std::size_t j = 0; j < q.x.size(); ++j) {
            // The hits' mean height on the tube: √(r² − y²) averaged over |y| ≤ 0.01 (r = 0.02).
            const double x = q.x[i], y = q.x[j], h = 1.0 - 0.01936;
            const double dist = std::sqrt(x * x + y * y + h * h);
            const Vec3 wi = frame.to_local(safe_normalize(Vec3{float(x), float(y), float(h)}));
            const Rgb m = blonde().dual->local_f_cos(std::asin(wi.x), 0.0f);
            for (int ch = 0; ch < 3; ++ch) want[ch] += q.w[i] * q.w[j] * h / (dist * dist * dist) * m[ch] * radiance;
        }
    const Estimate e = multiple_part(scene, 20000);
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(e.mean[ch], want[ch], 5.0 * e.sigma[ch] + 3e-3 * want[ch]) << "ch " << ch;
}

TEST(DualScatteringRender, ALoneHairUnderAnAreaLightIsSingleScatteringInALayer) {
    // Nothing behind the hair and nothing between it and the light: a layer's M is 0, and D
    // (light samples and the continuation's mixture, power heuristic over the mixture's
    // density) must equal the path tracer's single scattering, sample for sample in the mean.
    SceneDesc d = single_hair();
    d.area_lights = {rectangle_light({0.3f, 0, 1}, 1.5f, 1.0f, 20.0f)};
    const Scene scene = build(std::move(d));
    const RenderSettings dual = dual_settings(0, DualHairVolume::Layer);
    RenderSettings path = dual;
    path.integrator = int(Integrator::Path);
    const Estimate e = mean_difference(scene, dual, scene, path, 40000);
    for (int ch = 0; ch < 3; ++ch) {
        ASSERT_GT(e.reference[ch], 0.0);
        EXPECT_NEAR(e.mean[ch], 0.0, 5.0 * e.sigma[ch]) << "ch " << ch;
        EXPECT_LT(5.0 * e.sigma[ch], 0.02 * e.reference[ch]) << "resolves 2% of D, ch " << ch;
    }
}


// A tuft of wavy hairs standing on the XY plane: `count` curves of `points` points.
HairCurves tuft(int count, int points, float radius, std::uint32_t seed = 1) {
    std::uint32_t state = seed;
    auto u = [&] {  // uniform in [−1, 1)
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / float(1u << 23) - 1.0f;
    };
    HairCurves c;
    c.first.push_back(0);
    for (int i = 0; i < count; ++i) {
        const Vec3 root{0.3f * u(), 0.3f * u(), 0.0f};
        const Vec3 lean{0.3f * u(), 0.3f * u(), 1.0f};
        for (int k = 0; k < points; ++k) {
            const float t = float(k) / float(points - 1);
            const Vec3 wiggle{0.03f * std::sin(9.0f * t + float(i)), 0.03f * std::cos(7.0f * t + float(i)), 0.0f};
            c.points.push_back(root + lean * t + wiggle);
            c.radii.push_back(radius);
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    return c;
}

// A dense tuft of 1500 strands cut half-way up by a floor (so rays meet many strands, and
// some a mesh after them).
Scene tuft_cut_by_floor() {
    SceneDesc d;
    d.materials = {DiffuseMaterial{}, dual_hair(blonde())};
    d.curves = {tuft(1500, 6, 0.008f)};
    d.curves[0].material = 1;
    d.meshes = {quad_at(0.2f, 0.45f, 0)};
    d.camera = ortho_down(1, 1, 4, 4);
    return build(std::move(d));
}

TEST(TraceThroughHair, CappedTracesAgreeWithTheFullTrace) {
    // Random rays through a dense tuft cut by a floor half-way up: the capped count equals the
    // full trace's count, capped, for every cap, and a trace within a cap the full trace or its
    // first cap + 1 strands (the traversal stops early only once it knows).
    const Scene scene = tuft_cut_by_floor();
    std::vector<StrandCrossing> full, scratch;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    auto u = [&] { return uniform(rng); };
    int crossed_many = 0, stopped_by_mesh = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 origin{0.3f * u(), 0.3f * u(), 0.5f + 0.5f * u()};
        const Vec3 dir = safe_normalize(Vec3{u(), u(), 0.5f * u()});
        if (!(dot(dir, dir) > 0.0f)) continue;
        const auto mesh = scene.trace_through_hair(origin, dir, 0.0f, INFINITY, {}, {}, full);
        const int n = int(full.size());
        crossed_many += n > 16;
        stopped_by_mesh += mesh.has_value() && n > 0;
        for (const int cap : {1, 3, 16, 64})
            ASSERT_EQ(scene.strands_before_mesh(origin, dir, 0.0f, INFINITY, {}, cap, scratch), std::min(n, cap))
                << "ray " << i << " cap " << cap;
        // Within a cap: the full trace where it holds at most cap strands, else its first cap + 1.
        for (const int cap : {0, 1, 3, 16}) {
            const auto within = scene.trace_through_hair_within(origin, dir, 0.0f, INFINITY, {}, {}, cap, scratch);
            if (n > cap) {
                ASSERT_FALSE(within.has_value());
                ASSERT_EQ(scratch.size(), std::size_t(cap) + 1);
            } else {
                ASSERT_EQ(within.has_value(), mesh.has_value());
                if (mesh) {
                    ASSERT_EQ(within->t, mesh->t);
                }
                ASSERT_EQ(scratch.size(), full.size());
            }
            for (std::size_t k = 0; k < std::min(scratch.size(), std::size_t(cap) + 1); ++k)
                ASSERT_EQ(scratch[k].t, full[k].t) << "ray " << i << " cap " << cap << " crossing " << k;
        }
    }
    EXPECT_GT(crossed_many, 100);  // the caps were exercised
    EXPECT_GT(stopped_by_mesh, 100);
}

TEST(TraceThroughHair, StrandsBehindIsCountedOnceAndOnlyWhenAskedFor) {
    // A count of the strands behind traces strands_before_mesh's ray the first time a term can
    // use it and then keeps it; where the bounces left allow no strand behind it is 0, and
    // outside a layer −1, without a ray.
    const Scene scene = tuft_cut_by_floor();
    std::vector<StrandCrossing> scratch, reference;
    int counted = 0;
    for (int i = 0; i < 40; ++i) {
        const float a = 0.37f * float(i);
        const Vec3 origin{0.2f * std::cos(a), 0.2f * std::sin(a), 0.6f};
        const Vec3 dir = safe_normalize(Vec3{std::sin(a), std::cos(2.0f * a), -0.7f});
        const int want = scene.strands_before_mesh(origin, dir, 0.0f, INFINITY, {}, 5, reference);
        counted += want > 0;
        StrandsBehind behind{origin, dir, {}, 5};
        std::uint64_t rays = 0;
        // 4 events left after light through 3 strands: (4 − 3)/2 = 0 strands behind.
        ASSERT_EQ(behind.cut(scene, 3, 4, scratch, rays), 0) << "ray " << i;
        ASSERT_EQ(rays, 0u);
        ASSERT_EQ(behind.cut(scene, 0, -1, scratch, rays), want) << "ray " << i;
        ASSERT_EQ(rays, 1u);
        ASSERT_EQ(behind.cut(scene, 1, 8, scratch, rays), want);
        ASSERT_EQ(rays, 1u);
        StrandsBehind unbounded{origin, dir, {}, 5, false};
        ASSERT_EQ(unbounded.cut(scene, 0, -1, scratch, rays), -1);
        ASSERT_EQ(rays, 1u);
    }
    EXPECT_GT(counted, 10);  // most rays found strands
}

// A blonde tuft over a white floor under a sun and a grey world, seen by `camera`.
Scene tuft_over_floor(CameraDesc camera) {
    SceneDesc d;
    d.materials = {dual_hair(blonde()), DiffuseMaterial{}};
    d.curves = {tuft(300, 6, 0.006f)};
    d.meshes = {quad_at(1.0f, 0.0f, 1)};
    testing::set_sun(d, safe_normalize(Vec3{0.3f, -0.5f, 1.0f}), 2.0f);
    d.world = {Rgb(0.3f), 1.0f};
    d.camera = camera;
    return build(std::move(d));
}

TEST(DualScatteringRender, ExactBouncesArePathTracedAndTheClosureMovesWithThem) {
    // A blonde tuft over a floor under a sun and a world: with every bounce exact the dual
    // render is the path tracer's image bit for bit; with fewer, each exact bounce moves the
    // image, since the vertex that closes the path by dual scattering moves deeper.
    const Scene scene = tuft_over_floor(ortho_down(0.4f, 0.4f, 12, 12));
    RenderSettings path;
    path.samples = 4;
    path.max_bounces = 6;
    path.threads = 1;
    const std::size_t n = 12 * 12 * 4;
    std::vector<float> reference(n), image(n), previous(n);
    ASSERT_FALSE(render(scene, path, reference.data(), {}, nullptr));
    RenderSettings dual = path;
    dual.integrator = int(Integrator::DualScattering);
    for (const int exact : {7, 1024}) {
        dual.dual_exact_bounces = exact;
        ASSERT_FALSE(render(scene, dual, image.data(), {}, nullptr));
        EXPECT_TRUE(testing::same_bits(image, reference)) << "exact bounces " << exact;
    }
    for (const int exact : {0, 1, 2}) {
        dual.dual_exact_bounces = exact;
        ASSERT_FALSE(render(scene, dual, image.data(), {}, nullptr));
        EXPECT_FALSE(testing::same_bits(image, reference)) << "exact bounces " << exact;
        if (exact > 0) {
            EXPECT_FALSE(testing::same_bits(image, previous)) << "exact bounces " << exact;
        }
        previous = image;
    }
}

TEST(DualScatteringRender, AUniformMultipleTableGivesTheSameMeanWithMoreNoise) {
    // The multiple table drives the sampling of M: replaced by a uniform one (the uniform
    // sphere, same strand counts and nodes), the image's expectation stays (both estimators are
    // unbiased for the same integral) and its noise grows. A blonde tuft in a constant world:
    // M comes from table samples alone, and everything else draws the same numbers in both, so
    // the per-sample difference of the two renders is the difference of their M estimates.
    const Blonde &b = blonde();
    const MultipleTable &baked = *b.table;
    const auto uniform = std::make_shared<const MultipleTable>(
        MultipleTable::create(baked.theta_r_nodes(), baked.n_h_values(), baked.theta_i_count(),
                              std::vector<float>(baked.values().size(), 1.0f))
            .value());
    auto scene_with = [&](std::shared_ptr<const MultipleTable> table) {
        SceneDesc d;
        d.materials = {dual_hair(b, std::move(table))};
        d.curves = {tuft(400, 6, 0.004f)};
        d.world = {Rgb(1.0f), 1.0f};
        CameraDesc c;
        // At (0, −3, 0.6) looking along +Y, +Z up.
        const float m[16] = {1, 0, 0, 0, 0, 0, -1, -3, 0, 1, 0, 0.6f, 0, 0, 0, 1};
        c.camera_to_world = Mat4::from_row_major(m);
        c.frame = {Vec3{0.12f, 0.12f, -1}, Vec3{0.12f, -0.12f, -1}, Vec3{-0.12f, -0.12f, -1}, Vec3{-0.12f, 0.12f, -1}};
        c.width = 8;
        c.height = 8;
        d.camera = c;
        return build(std::move(d));
    };
    const Scene with_baked = scene_with(b.table), with_uniform = scene_with(uniform);
    RenderSettings s = dual_settings(4);
    s.film_transparent = false;
    const int n = 128;
    double diff_sum = 0, diff_sum2 = 0, var_baked = 0, var_uniform = 0, mean_baked = 0;
    int count = 0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            double sb = 0, sb2 = 0, su = 0, su2 = 0;
            for (std::uint64_t i = 0; i < std::uint64_t(n); ++i) {
                const double lb = luminance(render_sample(with_baked, s, x, y, i));
                const double lu = luminance(render_sample(with_uniform, s, x, y, i));
                sb += lb;
                sb2 += lb * lb;
                su += lu;
                su2 += lu * lu;
                diff_sum += lu - lb;
                diff_sum2 += (lu - lb) * (lu - lb);
                ++count;
            }
            var_baked += (sb2 - sb * sb / n) / (n - 1);
            var_uniform += (su2 - su * su / n) / (n - 1);
            mean_baked += sb / n;
        }
    mean_baked /= 64.0;
    const double diff_mean = diff_sum / count;
    const double diff_sigma = std::sqrt((diff_sum2 / count - diff_mean * diff_mean) / count);
    std::printf("mean %.5f, uniform − baked %.2e ± %.2e, per-sample variance baked %.3e uniform %.3e\n",
                mean_baked, diff_mean, diff_sigma, var_baked / 64, var_uniform / 64);
    EXPECT_GT(mean_baked, 0.05);
    EXPECT_LT(std::fabs(diff_mean), 4.0 * diff_sigma);
    EXPECT_GT(var_uniform, 1.5 * var_baked);
}

TEST(DualScatteringRender, WithNoBouncesLeftTheClosingVertexIsThePathTracersLastVertex) {
    // A blonde tuft over a floor under a sun and a world, Max Bounces = Exact Bounces = 2: the
    // vertices that close paths are at depth 2, where the path tracer's paths end, so nothing of
    // the multiple-scattering term may be added and the image's expectation is the path
    // tracer's (their estimators differ: the continuation's density is a mixture). With every
    // order (DualBounceLimit::None) it is brighter.
    const Scene scene = tuft_over_floor(ortho_down(0.3f, 0.3f, 1, 1));
    RenderSettings path;
    path.max_bounces = 2;
    path.threads = 1;
    RenderSettings limited = path, every_order = path;
    limited.integrator = every_order.integrator = int(Integrator::DualScattering);
    limited.dual_exact_bounces = every_order.dual_exact_bounces = 2;
    every_order.dual_bounce_limit = int(DualBounceLimit::None);
    const int n = 1500;
    const Estimate limited_minus_path = mean_difference(scene, limited, scene, path, n);
    const Estimate every_minus_path = mean_difference(scene, every_order, scene, path, n);
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_LT(std::fabs(limited_minus_path.mean[ch]), 4.0 * limited_minus_path.sigma[ch]) << "ch " << ch;
        EXPECT_GT(every_minus_path.mean[ch], 8.0 * every_minus_path.sigma[ch]) << "the test tells them apart, ch " << ch;
    }
}

}  // namespace
}  // namespace hairis
