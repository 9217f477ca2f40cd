#include "render/surface_bsdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "chi2.h"
#include "fiber/fresnel.h"
#include "fiber/ggx.h"
#include "hemisphere.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Chi2Result;
using testing::Sample3;

constexpr int kChi2Tests = 5;

SurfaceLobe lobe(SurfaceLobeKind kind, Rgb weight, float select) {
    SurfaceLobe l;
    l.kind = kind;
    l.weight = weight;
    l.select = select;
    return l;
}

SurfaceLobe microfacet(MicrofacetShadowing shadowing, MicrofacetFresnel fresnel, float alpha, Rgb weight,
                       float select) {
    SurfaceLobe l = lobe(SurfaceLobeKind::Microfacet, weight, select);
    l.shadowing = shadowing;
    l.fresnel = fresnel;
    l.alpha = alpha;
    l.shadowing_alpha2 = alpha * alpha;
    l.below_ng_is_zero = shadowing == MicrofacetShadowing::Correlated;
    return l;
}

// Cycles 3.4's Principled closures: diffuse, sheen, specular, clearcoat.
std::vector<SurfaceLobe> lobes_34() {
    SurfaceLobe diffuse = lobe(SurfaceLobeKind::PrincipledDiffuse, Rgb(0.5f, 0.4f, 0.3f), 0.4f);
    diffuse.roughness = 0.6f;
    SurfaceLobe sheen = lobe(SurfaceLobeKind::Sheen34, Rgb(0.3f), 0.05f);
    SurfaceLobe spec = microfacet(MicrofacetShadowing::Separable, MicrofacetFresnel::Interpolated34, 0.25f,
                                  Rgb(1.0f), 0.1f);
    spec.f0 = Rgb(0.04f, 0.05f, 0.06f);
    spec.ior = 1.5f;
    SurfaceLobe coat = microfacet(MicrofacetShadowing::Separable, MicrofacetFresnel::Interpolated34, 0.1f,
                                  Rgb(1.0f), 0.05f);
    coat.distribution = MicrofacetDistribution::Gtr1;
    coat.shadowing_alpha2 = 0.0625f;
    coat.f0 = Rgb(0.04f);
    coat.fresnel_scale = 0.25f;
    return {diffuse, sheen, spec, coat};
}

// Cycles 4.x's layered closures: coat, metal, specular, Oren–Nayar diffuse.
std::vector<SurfaceLobe> lobes_4() {
    SurfaceLobe coat = microfacet(MicrofacetShadowing::Correlated, MicrofacetFresnel::Dielectric, 0.3f,
                                  Rgb(0.5f), 0.1f);
    coat.ior = 1.6f;
    coat.energy_scale = 1.1f;
    SurfaceLobe metal = microfacet(MicrofacetShadowing::Correlated, MicrofacetFresnel::F82Tint, 0.45f,
                                   Rgb(0.3f), 0.2f);
    metal.f0 = Rgb(0.9f, 0.6f, 0.3f);
    metal.f82_b = Rgb(0.2f, 0.1f, 0.0f);
    SurfaceLobe spec = microfacet(MicrofacetShadowing::Correlated, MicrofacetFresnel::SchlickIor, 0.6f,
                                  Rgb(0.6f), 0.1f);
    spec.ior = 1.45f;
    spec.f0 = Rgb(0.034f);
    SurfaceLobe diffuse = lobe(SurfaceLobeKind::OrenNayar, Rgb(0.4f), 0.5f);
    diffuse.roughness = 0.7f;
    diffuse.multiscatter = Rgb(0.05f);
    return {coat, metal, spec, diffuse};
}

// lobes_34 with Cycles 3.4's clearcoat sampler and selection weights of its magnitude.
std::vector<SurfaceLobe> cycles_clearcoat_lobes() {
    std::vector<SurfaceLobe> lobes = lobes_34();
    lobes[3].sampling = MicrofacetSampling::Cycles34Clearcoat;
    lobes[3].select = 0.1f;
    return lobes;
}

SurfaceBsdf make_bsdf(const std::vector<SurfaceLobe> &lobes, Vec3 wo, Vec3 ng) {
    SurfaceBsdf b(Vec3{0, 0, 1}, ng, wo);
    for (const SurfaceLobe &l : lobes) EXPECT_TRUE(b.add(l));
    return b;
}

Chi2Result chi2(const SurfaceBsdf &b) {
    Chi2Options o;
    o.test_count = kChi2Tests;
    o.sin_theta_cells = 50;
    o.phi_cells = 100;
    return testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> {
            Vec3 wi;
            Rgb weight;
            float pdf;
            if (!b.sample(u.u0, u.u1, u.u2, wi, weight, pdf)) return std::nullopt;
            return wi;
        },
        [&](Vec3 wi) {
            float pdf = 0.0f;
            b.eval(wi, pdf);
            return double(pdf);
        },
        o);
}

TEST(SurfaceBsdf, MixtureSamplerMatchesItsDensity) {
    const Vec3 tilted_ng = safe_normalize(Vec3{0.35f, 0.1f, 1.0f});
    struct Case {
        const char *name;
        std::vector<SurfaceLobe> lobes;
        Vec3 wo, ng;
    };
    const std::vector<Case> cases = {
        {"3.4 principled", lobes_34(), testing::polar_direction(0.6, 0.3), Vec3{0, 0, 1}},
        {"3.4 principled, tilted ng, grazing", lobes_34(), testing::polar_direction(1.2, 2.0), tilted_ng},
        {"4.x layers, tilted ng", lobes_4(), testing::polar_direction(0.9, -0.5), tilted_ng},
        {"lambert", {lobe(SurfaceLobeKind::Lambert, Rgb(0.7f), 1.0f)}, testing::polar_direction(0.4, 0.0), Vec3{0, 0, 1}},
        {"3.4 principled, Cycles' clearcoat sampler", cycles_clearcoat_lobes(), testing::polar_direction(0.7, 0.5), Vec3{0, 0, 1}},
    };
    for (const Case &c : cases) {
        const SurfaceBsdf b = make_bsdf(c.lobes, c.wo, c.ng);
        const Chi2Result r = chi2(b);
        EXPECT_TRUE(r.passed) << c.name << ": " << r.message;
        EXPECT_NEAR(r.pdf_integral, 1.0 - double(r.failed_samples) / 1e6, 3e-3) << c.name;
    }
}

TEST(SurfaceBsdf, SampleWeightIsEvalOverPdf) {
    const SurfaceBsdf b = make_bsdf(lobes_4(), testing::polar_direction(0.7, 1.0), safe_normalize(Vec3{0.2f, 0.0f, 1.0f}));
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int drawn = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec3 wi;
        Rgb weight;
        float pdf;
        if (!b.sample(u(rng), u(rng), u(rng), wi, weight, pdf)) continue;
        ++drawn;
        float pdf2;
        const Rgb f = b.eval(wi, pdf2);
        EXPECT_NEAR(pdf2, pdf, 1e-4f * pdf);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(weight[k] * pdf, f[k], 1e-4f * (f[k] + 1e-6f));
    }
    EXPECT_GT(drawn, 1500);
}

TEST(SurfaceBsdf, SampleWeightsAverageToTheReflectedEnergy) {
    // The estimator E[f cos / pdf] over the sampler equals ∫ f cos over the directions it can
    // reach (above ng), by an independent quadrature of eval.
    const Vec3 ng = safe_normalize(Vec3{0.3f, -0.2f, 1.0f});
    for (const auto &lobes : {lobes_34(), lobes_4()}) {
        const SurfaceBsdf b = make_bsdf(lobes, testing::polar_direction(0.8, 0.4), ng);
        double quadrature[3] = {0, 0, 0};
        for (int k = 0; k < 3; ++k)
            quadrature[k] = testing::integrate_hemisphere([&](Vec3 wi) {
                if (!(dot(ng, wi) > 0.0f)) return 0.0;
                float pdf;
                return double(b.eval(wi, pdf)[k]);
            });
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        const int n = 400000;
        double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
        for (int i = 0; i < n; ++i) {
            Vec3 wi;
            Rgb weight;
            float pdf;
            if (!b.sample(u(rng), u(rng), u(rng), wi, weight, pdf)) continue;
            for (int k = 0; k < 3; ++k) {
                sum[k] += weight[k];
                sum2[k] += double(weight[k]) * weight[k];
            }
        }
        for (int k = 0; k < 3; ++k) {
            const double mean = sum[k] / n, sd = std::sqrt((sum2[k] / n - mean * mean) / n);
            EXPECT_NEAR(mean, quadrature[k], 5.0 * sd + 1e-4) << "channel " << k;
        }
    }
}

TEST(SurfaceBsdf, CyclesClearcoatWeightsByTheDensityItReports) {
    // Cycles 3.4's clearcoat is drawn from GGX visible normals but weighted with its GTR1
    // formula: the sample's pdf is the true mixture Q, its weight f / P with P the reported
    // mixture, so the mean weight is ∫ f Q / P (not ∫ f), by quadrature here.
    const SurfaceBsdf b = make_bsdf(cycles_clearcoat_lobes(), testing::polar_direction(0.8, 0.4), Vec3{0, 0, 1});
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const int n = 400000;
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
        Vec3 wi;
        Rgb weight;
        float pdf;
        if (!b.sample(u(rng), u(rng), u(rng), wi, weight, pdf)) continue;
        float q, p;
        const Rgb f = b.eval(wi, q, &p);
        ASSERT_NEAR(q, pdf, 1e-4f * pdf);
        ASSERT_NEAR(weight.g * p, f.g, 1e-4f * f.g + 1e-7f);
        sum += weight.g;
        sum2 += double(weight.g) * weight.g;
    }
    const auto integral = [&](bool cycles) {
        return testing::integrate_hemisphere([&](Vec3 wi) {
            float q, p;
            const double f = b.eval(wi, q, &p).g;
            return cycles ? (p > 0.0f ? f * q / p : 0.0) : f;
        }, 192, 192);
    };
    const double mean = sum / n, sd = std::sqrt((sum2 / n - mean * mean) / n);
    const double cycles = integral(true), exact = integral(false);
    EXPECT_NEAR(mean, cycles, 5.0 * sd);
    EXPECT_GT(std::fabs(cycles - exact), 10.0 * sd) << "the test must tell the two apart";
    // The exact lobes report what they draw: P = Q.
    const SurfaceBsdf plain = make_bsdf(lobes_34(), testing::polar_direction(0.8, 0.4), Vec3{0, 0, 1});
    for (double t : {0.1, 0.7, 1.3}) {
        float q, p;
        plain.eval(testing::polar_direction(t, 3.0), q, &p);
        EXPECT_EQ(q, p);
    }
}

// Cycles' bsdf_blur (Filter Glossy): a microfacet lobe below the blur becomes the same lobe at
// the blur's α (its GGX shadowing with it; 3.4's GTR1 clearcoat keeps its fixed one); lobes at
// or above it and diffuse lobes are untouched.
TEST(SurfaceBsdf, BlurRaisesMicrofacetRoughnessAsCycles) {
    const Vec3 wo = testing::polar_direction(0.6, 0.3), ng{0, 0, 1};
    SurfaceBsdf b = make_bsdf(lobes_34(), wo, ng);
    b.blur(0.2f);
    EXPECT_EQ(b.lobe(0).roughness, 0.6f);  // the diffuse lobe
    EXPECT_EQ(b.lobe(2).alpha, 0.25f);     // above the blur
    EXPECT_EQ(b.lobe(3).alpha, 0.2f);      // the clearcoat, raised
    EXPECT_EQ(b.lobe(3).shadowing_alpha2, 0.0625f);
    std::vector<SurfaceLobe> wider = lobes_34();
    wider[3].alpha = 0.2f;
    const SurfaceBsdf want = make_bsdf(wider, wo, ng);
    SurfaceBsdf ggx = make_bsdf(lobes_4(), wo, ng);
    ggx.blur(0.4f);
    std::vector<SurfaceLobe> ggx_wider = lobes_4();
    for (SurfaceLobe &l : ggx_wider)
        if (l.kind == SurfaceLobeKind::Microfacet && l.alpha < 0.4f) {
            l.alpha = 0.4f;
            l.shadowing_alpha2 = 0.16f;
        }
    const SurfaceBsdf ggx_want = make_bsdf(ggx_wider, wo, ng);
    for (const Vec3 wi : {testing::polar_direction(0.5, 3.0), testing::polar_direction(0.2, 1.0)}) {
        float p = 0, q = 0;
        const Rgb f = b.eval(wi, p), g = want.eval(wi, q);
        EXPECT_NEAR(f.r, g.r, 1e-6f * std::max(1.0f, g.r));
        EXPECT_NEAR(p, q, 1e-6f * std::max(1.0f, q));
        const Rgb f4 = ggx.eval(wi, p), g4 = ggx_want.eval(wi, q);
        EXPECT_NEAR(f4.g, g4.g, 1e-6f * std::max(1.0f, g4.g));
        EXPECT_NEAR(p, q, 1e-6f * std::max(1.0f, q));
    }
    // The blur did change the image: the raised lobe is not the original one.
    const SurfaceBsdf before = make_bsdf(lobes_4(), wo, ng);
    float p = 0, q = 0;
    const Vec3 mirror{-wo.x, -wo.y, wo.z};
    EXPECT_GT(std::fabs(before.eval(mirror, p).r - ggx.eval(mirror, q).r), 1e-3f);
}

TEST(SurfaceBsdf, DefensiveSelectionRaisesSmallLobes) {
    SurfaceBsdf b = make_bsdf(lobes_34(), testing::polar_direction(0.5, 0.0), Vec3{0, 0, 1});
    const float total = 0.4f + 0.05f + 0.1f + 0.05f;
    b.defend_selection(0.125f);
    EXPECT_FLOAT_EQ(b.lobe(0).select, 0.4f);
    EXPECT_FLOAT_EQ(b.lobe(1).select, 0.125f * total);
    EXPECT_FLOAT_EQ(b.lobe(2).select, 0.1f);
    EXPECT_FLOAT_EQ(b.lobe(3).select, 0.125f * total);
}

TEST(SurfaceBsdf, LambertReflectsItsWeight) {
    const SurfaceBsdf b = make_bsdf({lobe(SurfaceLobeKind::Lambert, Rgb(0.8f, 0.5f, 0.2f), 1.0f)},
                                    testing::polar_direction(0.5, 0.0), Vec3{0, 0, 1});
    const double albedo = testing::integrate_hemisphere([&](Vec3 wi) {
        float pdf;
        return double(b.eval(wi, pdf).g);
    });
    EXPECT_NEAR(albedo, 0.5, 1e-5);
}

double lobe_albedo(const SurfaceLobe &l, Vec3 wo, int channel = 0) {
    return testing::integrate_hemisphere([&](Vec3 wi) {
        float pdf;
        return double(eval_lobe(l, wo, wi, pdf)[channel]);
    });
}

TEST(SurfaceBsdf, PrincipledDiffuseAlbedoAtNormalIncidence) {
    // Roughness 0, ω_o = n: F_o = 0 and ∫ (1 − (1 − c)^5/2) 2c dc = 1 − 1/42.
    SurfaceLobe l = lobe(SurfaceLobeKind::PrincipledDiffuse, Rgb(1.0f), 1.0f);
    EXPECT_NEAR(lobe_albedo(l, Vec3{0, 0, 1}), 41.0 / 42.0, 1e-5);
    // Retro-reflection adds energy with roughness (Burley's model is not energy conserving).
    l.roughness = 1.0f;
    EXPECT_GT(lobe_albedo(l, testing::polar_direction(1.2, 0.0)), 1.0);
}

TEST(SurfaceBsdf, OrenNayarVersions) {
    // σ = 0 is Lambert in both; 4.3+'s model with its multiple scattering preserves energy
    // (white furnace), 3.4's loses some.
    SurfaceLobe old_on = lobe(SurfaceLobeKind::OrenNayar34, Rgb(1.0f), 1.0f);
    EXPECT_NEAR(lobe_albedo(old_on, testing::polar_direction(0.7, 0.0)), 1.0, 1e-5);
    old_on.roughness = 1.0f;
    EXPECT_LT(lobe_albedo(old_on, testing::polar_direction(0.7, 0.0)), 0.98);

    // The multiple-scattering colour for a white albedo and this ω_o, from OpenPBR's formula
    // written out here: E(c) = Aπ + B G(c), E_avg = Aπ + (2π − 5.6) B / 3,
    // M = (1/π) E_avg / (1 − E_avg) / (1 − (1 − E_avg)) (1 − E(c_o)).
    for (double sigma : {0.3, 1.0})
        for (double theta : {0.2, 1.1}) {
            const double pi = kPi, a = 1.0 / (pi + sigma * (pi / 2 - 2.0 / 3.0)), b = sigma * a;
            const double co = std::cos(theta), so = std::sin(theta);
            const double g = so * (theta - 2.0 / 3.0 - so * co) + 2.0 / 3.0 * (so / co) * (1 - so * so * so);
            const double e_avg = a * pi + (2 * pi - 5.6) / 3.0 * b;
            const double ems = (1.0 / pi) * (e_avg / (1.0 - e_avg)) / (1.0 - (1.0 - e_avg));
            SurfaceLobe on = lobe(SurfaceLobeKind::OrenNayar, Rgb(1.0f), 1.0f);
            on.roughness = float(sigma);
            on.multiscatter = Rgb(float(ems * (1.0 - (a * pi + b * g))));
            EXPECT_NEAR(lobe_albedo(on, testing::polar_direction(theta, 0.0)), 1.0, 5e-3) << sigma << " " << theta;
        }
}

// Cycles' microfacet reflection from its formulas, in double with lib/fiber/ggx's D and Λ.
double reference_microfacet(const SurfaceLobe &l, Vec3 wo, Vec3 wi, int channel) {
    const Vec3d o{wo.x, wo.y, wo.z}, i{wi.x, wi.y, wi.z};
    const Vec3d hs = o + i;
    const Vec3d h = hs / std::sqrt(dot(hs, hs));
    const double c = dot(i, h), alpha = l.alpha;
    double d;
    if (l.distribution == MicrofacetDistribution::Gtr1) {
        const double a2 = alpha * alpha;
        d = (a2 - 1.0) / (kPi * std::log(a2) * (1.0 + (a2 - 1.0) * h.z * h.z));
    } else {
        d = ggx::distribution(alpha, h.z);
    }
    const double ag = std::sqrt(double(l.shadowing_alpha2));
    const double g = l.shadowing == MicrofacetShadowing::Separable
                         ? ggx::shadowing_g1(ag, o.z) * ggx::shadowing_g1(ag, i.z)
                         : ggx::shadowing_g2(ag, o.z, i.z);
    const double f0 = l.f0[channel];
    double f = 1.0;
    switch (l.fresnel) {
        case MicrofacetFresnel::One: break;
        case MicrofacetFresnel::Interpolated34: {
            const double r0 = fresnel_dielectric(1.0, double(l.ior));
            const double s = (fresnel_dielectric(c, double(l.ior)) - r0) / (1.0 - r0);
            f = (f0 * (1.0 - s) + s) * l.fresnel_scale;
            break;
        }
        case MicrofacetFresnel::SchlickIor: {
            const double r0 = sqr((l.ior - 1.0) / (l.ior + 1.0));
            const double s = std::clamp((fresnel_dielectric(c, double(l.ior)) - r0) / (1.0 - r0), 0.0, 1.0);
            f = f0 + (1.0 - f0) * s;
            break;
        }
        case MicrofacetFresnel::F82Tint: {
            const double m = 1.0 - c;
            f = std::clamp(f0 + (1.0 - f0) * std::pow(m, 5) - l.f82_b[channel] * c * std::pow(m, 6), 0.0, 1.0);
            break;
        }
        case MicrofacetFresnel::Dielectric: f = fresnel_dielectric(c, double(l.ior)); break;
    }
    return f * d * g * l.energy_scale / (4.0 * o.z);
}

TEST(SurfaceBsdf, MicrofacetLobesFollowCyclesFormulas) {
    std::vector<SurfaceLobe> all = lobes_34();
    for (const SurfaceLobe &l : lobes_4()) all.push_back(l);
    for (const SurfaceLobe &l : all) {
        if (l.kind != SurfaceLobeKind::Microfacet) continue;
        for (const auto &[to, ti, dphi] : {std::tuple{0.3, 0.5, 2.8}, {1.1, 0.9, 3.2}, {0.8, 1.3, 1.0}}) {
            const Vec3 wo = testing::polar_direction(to, 0.0), wi = testing::polar_direction(ti, dphi);
            float pdf;
            const Rgb v = eval_lobe(l, wo, wi, pdf);
            for (int k = 0; k < 3; ++k) {
                const double expected = reference_microfacet(l, wo, wi, k);
                EXPECT_NEAR(v[k], expected, 1e-4 * expected + 1e-7);
            }
        }
    }
}

TEST(SurfaceBsdf, ReflectionLobesAreZeroBelowTheNormalAndCycles4MicrofacetsBelowNg) {
    const Vec3 ng = safe_normalize(Vec3{0.5f, 0.0f, 1.0f});
    const Vec3 wo = testing::polar_direction(0.5, 0.0);
    // Above n (z > 0) but below ng (x·0.5 + z < 0).
    const Vec3 wi = safe_normalize(Vec3{-1.0f, 0.0f, 0.3f});
    ASSERT_GT(wi.z, 0.0f);
    ASSERT_LT(dot(ng, wi), 0.0f);
    for (const SurfaceLobe &l : lobes_4()) {
        SurfaceBsdf b(Vec3{0, 0, 1}, ng, wo);
        b.add(l);
        float pdf = 1.0f;
        const Rgb f = b.eval(wi, pdf);
        EXPECT_EQ(pdf, 0.0f);
        if (l.below_ng_is_zero) EXPECT_EQ(f.max_component(), 0.0f);
        else EXPECT_GT(f.max_component(), 0.0f);  // Cycles' diffuse lobes test n only
    }
    for (const SurfaceLobe &l : lobes_34()) {
        float pdf;
        EXPECT_EQ(eval_lobe(l, wo, testing::polar_direction(1.8, 0.3), pdf).max_component(), 0.0f);
    }
}

TEST(SurfaceBsdf, LobesBeyondCapacityAreRefused) {
    SurfaceBsdf b(Vec3{0, 0, 1}, Vec3{0, 0, 1}, Vec3{0, 0, 1});
    for (int i = 0; i < SurfaceBsdf::kMaxLobes; ++i) EXPECT_TRUE(b.add(lobe(SurfaceLobeKind::Lambert, Rgb(0.01f), 1.0f)));
    EXPECT_FALSE(b.add(lobe(SurfaceLobeKind::Lambert, Rgb(0.01f), 1.0f)));
    // Zero weights are not lobes.
    EXPECT_TRUE(b.add(lobe(SurfaceLobeKind::Lambert, Rgb(0.0f), 1.0f)));
    EXPECT_EQ(b.lobe_count(), SurfaceBsdf::kMaxLobes);
}

}  // namespace
}  // namespace hairis
