#include "fiber/principled_hair.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace hairis {
namespace {

// The documented formulas, written out independently of the implementation.
constexpr double kEumelanin[3] = {0.506, 0.841, 1.653};
constexpr double kPheomelanin[3] = {0.343, 0.733, 1.924};

double roughness_polynomial(double x) {
    return 5.969 - 0.215 * x + 2.532 * x * x - 10.73 * std::pow(x, 3) + 5.574 * std::pow(x, 4) +
           0.245 * std::pow(x, 5);
}

double sigma_of_colour(double c, double radial_roughness) {
    return sqr(std::log(c) / roughness_polynomial(radial_roughness));
}

void expect_rgb_near(Rgb actual, double r, double g, double b, double relative, const std::string &what) {
    EXPECT_NEAR(actual.r, r, relative * std::fabs(r) + 1e-7) << what << " (red)";
    EXPECT_NEAR(actual.g, g, relative * std::fabs(g) + 1e-7) << what << " (green)";
    EXPECT_NEAR(actual.b, b, relative * std::fabs(b) + 1e-7) << what << " (blue)";
}

ChiangParams mapped(const PrincipledHairNode &node) {
    Expected<ChiangParams> params = to_chiang_params(node);
    EXPECT_TRUE(params.ok()) << (params.ok() ? "" : params.error().message);
    return params.ok() ? params.value() : ChiangParams{};
}

TEST(PrincipledHairNode, DefaultsAreBlenders) {
    // node_shader_bsdf_hair_principled.cc (Blender 2.80–3.4, unchanged in 4.x).
    const PrincipledHairNode node;
    EXPECT_EQ(node.parametrization, HairParametrization::Color);  // SHD_PRINCIPLED_HAIR_REFLECTANCE
    EXPECT_EQ(node.color.r, 0.017513f);
    EXPECT_EQ(node.color.g, 0.005763f);
    EXPECT_EQ(node.color.b, 0.002059f);
    EXPECT_EQ(node.melanin, 0.8f);
    EXPECT_EQ(node.melanin_redness, 1.0f);
    EXPECT_EQ(node.tint.r, 1.0f);
    EXPECT_EQ(node.tint.g, 1.0f);
    EXPECT_EQ(node.tint.b, 1.0f);
    EXPECT_EQ(node.absorption_coefficient.r, 0.245531f);
    EXPECT_EQ(node.absorption_coefficient.g, 0.52f);
    EXPECT_EQ(node.absorption_coefficient.b, 1.365f);
    EXPECT_EQ(node.roughness, 0.3f);
    EXPECT_EQ(node.radial_roughness, 0.3f);
    EXPECT_EQ(node.coat, 0.0f);
    EXPECT_EQ(node.ior, 1.55f);
    EXPECT_EQ(node.offset, 2.0f * float(kPi) / 180.0f);
    EXPECT_EQ(node.random_color, 0.0f);
    EXPECT_EQ(node.random_roughness, 0.0f);
    EXPECT_EQ(node.random, 0.0f);

    const PrincipledHairNode preset = PrincipledHairNode::cycles_default();
    EXPECT_EQ(preset.parametrization, node.parametrization);
    EXPECT_EQ(preset.color.b, node.color.b);
    EXPECT_EQ(preset.offset, node.offset);
}

TEST(PrincipledHairNode, DefaultNodeMakesAValidFiber) {
    const ChiangParams params = mapped(PrincipledHairNode::cycles_default());
    EXPECT_TRUE(ChiangFiber::create(params).ok());
    // Direct Coloring of the default colour at radial roughness 0.3.
    expect_rgb_near(params.sigma_a, sigma_of_colour(0.017513, 0.3), sigma_of_colour(0.005763, 0.3),
                    sigma_of_colour(0.002059, 0.3), 1e-5, "default sigma_a");
    EXPECT_EQ(params.roughness, 0.3f);
    EXPECT_EQ(params.radial_roughness, 0.3f);
    EXPECT_EQ(params.coat, 0.0f);
    EXPECT_EQ(params.ior, 1.55f);
    EXPECT_EQ(params.offset, float(radians(2.0)));
}

TEST(PrincipledHairMapping, AbsorptionCoefficientIsPassedThrough) {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::AbsorptionCoefficient;
    node.absorption_coefficient = {0.1f, 2.0f, 30.0f};
    node.color = {std::nanf(""), -1.0f, 0.0f};  // hidden sockets are not read
    node.melanin = std::nanf("");
    node.roughness = 0.55f;
    node.radial_roughness = 0.15f;
    node.coat = 0.25f;
    node.ior = 1.4f;
    node.offset = float(radians(-3.0));
    const ChiangParams params = mapped(node);
    expect_rgb_near(params.sigma_a, 0.1, 2.0, 30.0, 0.0, "sigma_a");
    EXPECT_EQ(params.roughness, 0.55f);
    EXPECT_EQ(params.radial_roughness, 0.15f);
    EXPECT_EQ(params.coat, 0.25f);
    EXPECT_EQ(params.ior, 1.4f);
    EXPECT_EQ(params.offset, float(radians(-3.0)));
}

TEST(PrincipledHairMapping, MelaninConcentration) {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::Melanin;

    // Melanin 0.5, redness 0: σ = −log(0.5)·eumelanin colour; tint white adds nothing.
    node.melanin = 0.5f;
    node.melanin_redness = 0.0f;
    double m = -std::log(0.5);
    expect_rgb_near(mapped(node).sigma_a, m * kEumelanin[0], m * kEumelanin[1], m * kEumelanin[2], 1e-6,
                    "melanin 0.5, redness 0");

    // Blender's defaults: melanin 0.8, all pheomelanin.
    node.melanin = 0.8f;
    node.melanin_redness = 1.0f;
    m = -std::log(1.0 - double(0.8f));
    expect_rgb_near(mapped(node).sigma_a, m * kPheomelanin[0], m * kPheomelanin[1], m * kPheomelanin[2], 1e-6,
                    "melanin 0.8, redness 1");

    // A mix: redness 0.25 splits the concentration.
    node.melanin = 0.3f;
    node.melanin_redness = 0.25f;
    m = -std::log(1.0 - double(0.3f));
    expect_rgb_near(mapped(node).sigma_a, m * (0.75 * kEumelanin[0] + 0.25 * kPheomelanin[0]),
                    m * (0.75 * kEumelanin[1] + 0.25 * kPheomelanin[1]),
                    m * (0.75 * kEumelanin[2] + 0.25 * kPheomelanin[2]), 1e-6, "melanin 0.3, redness 0.25");

    // Melanin 1 is capped at −log(1e-4).
    node.melanin = 1.0f;
    node.melanin_redness = 0.0f;
    m = -std::log(1e-4);
    expect_rgb_near(mapped(node).sigma_a, m * kEumelanin[0], m * kEumelanin[1], m * kEumelanin[2], 1e-6,
                    "melanin 1");

    // A tint adds sigma_from_reflectance(tint, radial roughness).
    node.melanin = 0.0f;
    node.tint = {0.5f, 0.25f, 1.0f};
    node.radial_roughness = 0.4f;
    expect_rgb_near(mapped(node).sigma_a, sigma_of_colour(0.5, 0.4f), sigma_of_colour(0.25, 0.4f), 0.0, 1e-5,
                    "tint only");
}

TEST(PrincipledHairMapping, RandomColorScalesMelaninBeforeTheRemapping) {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::Melanin;
    node.melanin = 0.5f;
    node.melanin_redness = 0.0f;
    node.random_color = 0.5f;
    node.random = 1.0f;  // factor 1 + 2·(1 − 0.5)·0.5 = 1.5 → melanin 0.75
    double m = -std::log(1.0 - 0.75);
    expect_rgb_near(mapped(node).sigma_a, m * kEumelanin[0], m * kEumelanin[1], m * kEumelanin[2], 1e-6,
                    "random 1");
    node.random = 0.0f;  // factor 0.5 → melanin 0.25
    m = -std::log(1.0 - 0.25);
    expect_rgb_near(mapped(node).sigma_a, m * kEumelanin[0], m * kEumelanin[1], m * kEumelanin[2], 1e-6,
                    "random 0");
    node.melanin = 0.9f;  // factor 1.9 pushes it past 1: capped
    node.random_color = 0.9f;
    node.random = 1.0f;
    m = -std::log(1e-4);
    expect_rgb_near(mapped(node).sigma_a, m * kEumelanin[0], m * kEumelanin[1], m * kEumelanin[2], 1e-6,
                    "randomized past 1");
}

TEST(PrincipledHairMapping, RandomRoughnessScalesBothRoughnessesAndTheColourInversion) {
    PrincipledHairNode node;
    node.roughness = 0.3f;
    node.radial_roughness = 0.4f;
    node.random_roughness = 0.5f;
    node.random = 1.0f;  // factor 1.5
    ChiangParams params = mapped(node);
    EXPECT_NEAR(params.roughness, 0.45, 1e-6);
    EXPECT_NEAR(params.radial_roughness, 0.6, 1e-6);
    // Direct Coloring inverts the colour with the randomized radial roughness.
    expect_rgb_near(params.sigma_a, sigma_of_colour(node.color.r, 1.5 * double(0.4f)),
                    sigma_of_colour(node.color.g, 1.5 * double(0.4f)),
                    sigma_of_colour(node.color.b, 1.5 * double(0.4f)), 1e-5, "colour with random roughness");

    // Past 1 the roughnesses are clamped (Cycles' setup clamp), but the colour inversion sees
    // the unclamped radial roughness, as in Cycles' SVM code.
    node.roughness = 0.9f;
    node.radial_roughness = 0.8f;
    node.random_roughness = 1.0f;  // factor 2
    params = mapped(node);
    EXPECT_EQ(params.roughness, 1.0f);
    EXPECT_EQ(params.radial_roughness, 1.0f);
    expect_rgb_near(params.sigma_a, sigma_of_colour(node.color.r, 2.0 * double(0.8f)),
                    sigma_of_colour(node.color.g, 2.0 * double(0.8f)),
                    sigma_of_colour(node.color.b, 2.0 * double(0.8f)), 1e-5, "unclamped radial roughness");

    node.random = 0.0f;  // factor 0
    params = mapped(node);
    EXPECT_EQ(params.roughness, 0.0f);
    EXPECT_EQ(params.radial_roughness, 0.0f);
}

TEST(PrincipledHairMapping, BuildingBlocksMatchTheFormulas) {
    for (double x : {0.0, 0.3, 0.7, 1.0, 1.6}) {
        EXPECT_NEAR(principled_hair::albedo_roughness_scale(x), roughness_polynomial(x), 1e-12);
    }
    expect_rgb_near(principled_hair::sigma_from_reflectance({0.2f, 0.5f, 1.0f}, 0.3),
                    sigma_of_colour(double(0.2f), 0.3), sigma_of_colour(0.5, 0.3), 0.0, 1e-6, "reflectance");
    // Cycles' colour inversion is symmetric in log: c and 1/c give the same σ.
    expect_rgb_near(principled_hair::sigma_from_reflectance({2.0f, 4.0f, 1.0f}, 0.3),
                    sigma_of_colour(0.5, 0.3), sigma_of_colour(0.25, 0.3), 0.0, 1e-6, "reciprocal colour");
    expect_rgb_near(principled_hair::sigma_from_concentration(2.0, 3.0), 2 * kEumelanin[0] + 3 * kPheomelanin[0],
                    2 * kEumelanin[1] + 3 * kPheomelanin[1], 2 * kEumelanin[2] + 3 * kPheomelanin[2], 1e-6,
                    "concentration");
}

TEST(PrincipledHairMapping, EachInvalidInputIsRefusedByName) {
    const float nan = std::nanf("");
    struct Case {
        HairParametrization parametrization;
        std::function<void(PrincipledHairNode &)> spoil;
        std::string name;
    };
    using P = HairParametrization;
    const std::vector<Case> cases = {
        {P::Color, [&](PrincipledHairNode &n) { n.roughness = nan; }, "roughness"},
        {P::Color, [](PrincipledHairNode &n) { n.roughness = 1.2f; }, "roughness"},
        {P::Color, [](PrincipledHairNode &n) { n.radial_roughness = -0.2f; }, "radial_roughness"},
        {P::Color, [](PrincipledHairNode &n) { n.coat = 1.5f; }, "coat"},
        {P::Color, [](PrincipledHairNode &n) { n.ior = 1.0f; }, "ior"},
        {P::Color, [](PrincipledHairNode &n) { n.ior = 0.0f; }, "ior"},
        {P::Color, [](PrincipledHairNode &n) { n.offset = 3.0f; }, "offset"},
        {P::Color, [](PrincipledHairNode &n) { n.random_roughness = 2.0f; }, "random_roughness"},
        {P::Color, [](PrincipledHairNode &n) { n.random = -0.1f; }, "random"},
        {P::Color, [&](PrincipledHairNode &n) { n.random = nan; }, "random"},
        {P::Color, [](PrincipledHairNode &n) { n.color.r = 0.0f; }, "color.r"},
        {P::Color, [&](PrincipledHairNode &n) { n.color.g = nan; }, "color.g"},
        {P::Color, [](PrincipledHairNode &n) { n.color.b = -0.5f; }, "color.b"},
        {P::Color, [](PrincipledHairNode &n) { n.color.b = INFINITY; }, "color.b"},
        {P::Melanin, [](PrincipledHairNode &n) { n.melanin = 1.5f; }, "melanin"},
        {P::Melanin, [](PrincipledHairNode &n) { n.melanin = -0.1f; }, "melanin"},
        {P::Melanin, [&](PrincipledHairNode &n) { n.melanin_redness = nan; }, "melanin_redness"},
        {P::Melanin, [](PrincipledHairNode &n) { n.random_color = 2.0f; }, "random_color"},
        {P::Melanin, [](PrincipledHairNode &n) { n.tint.g = 0.0f; }, "tint.g"},
        {P::Melanin, [](PrincipledHairNode &n) { n.tint.b = -1.0f; }, "tint.b"},
        {P::AbsorptionCoefficient, [](PrincipledHairNode &n) { n.absorption_coefficient.r = -0.1f; },
         "absorption_coefficient.r"},
        {P::AbsorptionCoefficient, [&](PrincipledHairNode &n) { n.absorption_coefficient.b = nan; },
         "absorption_coefficient.b"},
        {P::Color, [](PrincipledHairNode &n) { n.parametrization = static_cast<HairParametrization>(7); },
         "parametrization"},
    };
    for (const Case &c : cases) {
        PrincipledHairNode node;
        node.parametrization = c.parametrization;
        c.spoil(node);
        Expected<ChiangParams> params = to_chiang_params(node);
        ASSERT_FALSE(params.ok()) << c.name;
        EXPECT_NE(params.error().message.find(c.name), std::string::npos)
            << "message '" << params.error().message << "' does not name " << c.name;
    }
}

TEST(PrincipledHairMapping, EveryValidNodeMakesAValidFiber) {
    for (HairParametrization parametrization :
         {HairParametrization::AbsorptionCoefficient, HairParametrization::Melanin, HairParametrization::Color}) {
        for (float random : {0.0f, 0.5f, 1.0f}) {
            for (float extreme : {0.0f, 1.0f}) {
                PrincipledHairNode node;
                node.parametrization = parametrization;
                node.random = random;
                node.random_color = extreme;
                node.random_roughness = extreme;
                node.roughness = extreme;
                node.radial_roughness = extreme;
                node.melanin = extreme;
                node.melanin_redness = extreme;
                node.coat = extreme;
                Expected<ChiangParams> params = to_chiang_params(node);
                ASSERT_TRUE(params.ok()) << params.error().message;
                Expected<ChiangFiber> fiber = ChiangFiber::create(params.value());
                EXPECT_TRUE(fiber.ok()) << fiber.error().message;
            }
        }
    }
}

}  // namespace
}  // namespace hairis

namespace hairis {
namespace {

HuangParams mapped_huang(const PrincipledHairNode &node) {
    Expected<HuangParams> params = to_huang_params(node);
    EXPECT_TRUE(params.ok()) << (params.ok() ? "" : params.error().message);
    return params.ok() ? params.value() : HuangParams{};
}

TEST(PrincipledHairHuang, DefaultNodeMapsToCyclesHuangDefaults) {
    const PrincipledHairNode node;  // Blender's node with model Huang: aspect 0.85, lobes 1
    const HuangParams p = mapped_huang(node);
    EXPECT_FLOAT_EQ(p.aspect_ratio, 0.85f);
    EXPECT_EQ(p.reflection, 1.0f);
    EXPECT_EQ(p.transmission, 1.0f);
    EXPECT_EQ(p.secondary_reflection, 1.0f);
    EXPECT_FLOAT_EQ(p.roughness, 0.3f);
    EXPECT_FLOAT_EQ(p.ior, 1.55f);
    EXPECT_FLOAT_EQ(p.offset, float(radians(2.0)));
    // Direct Coloring with Huang inverts the colour with Roughness.
    expect_rgb_near(p.sigma_a, sigma_of_colour(node.color.r, double(0.3f)), sigma_of_colour(node.color.g, double(0.3f)),
                    sigma_of_colour(node.color.b, double(0.3f)), 1e-5, "default colour");
    EXPECT_TRUE(HuangFiber::create(p).ok());
}

TEST(PrincipledHairHuang, ColourUsesRoughnessWhereChiangUsesRadialRoughness) {
    for (HairParametrization parametrization : {HairParametrization::Color, HairParametrization::Melanin}) {
        PrincipledHairNode node;
        node.parametrization = parametrization;
        node.tint = {0.6f, 0.5f, 0.4f};
        node.roughness = 0.2f;
        node.radial_roughness = 0.7f;
        node.random_roughness = 0.5f;
        node.random = 0.9f;  // factor 1.4
        const HuangParams huang = mapped_huang(node);
        // The same node for Chiang with the radial roughness set to Huang's roughness gives
        // Huang's σ; with its own radial roughness it differs.
        PrincipledHairNode as_chiang = node;
        as_chiang.radial_roughness = node.roughness;
        const Rgb expected = mapped(as_chiang).sigma_a;
        expect_rgb_near(huang.sigma_a, expected.r, expected.g, expected.b, 1e-6, "σ from roughness");
        EXPECT_GT(std::fabs(mapped(node).sigma_a.r - huang.sigma_a.r), 1e-3f);
        EXPECT_NEAR(huang.roughness, 0.2 * 1.4, 1e-6);
    }
    // Past 1 the roughness is clamped, the colour still inverts with the randomized value.
    PrincipledHairNode rough;
    rough.roughness = 0.8f;
    rough.random_roughness = 1.0f;
    rough.random = 1.0f;  // factor 2
    const HuangParams p = mapped_huang(rough);
    EXPECT_EQ(p.roughness, 1.0f);
    expect_rgb_near(p.sigma_a, sigma_of_colour(rough.color.r, 1.6), sigma_of_colour(rough.color.g, 1.6),
                    sigma_of_colour(rough.color.b, 1.6), 1e-5, "unclamped roughness");
}

TEST(PrincipledHairHuang, LobesAndAspectRatioFollowCycles) {
    PrincipledHairNode node;
    node.reflection = -0.5f;  // Cycles: max(0, value)
    node.transmission = 0.5f;
    node.secondary_reflection = 3.0f;  // no upper clamp
    node.aspect_ratio = 2.0f;          // passed on; the fiber renders it as 1/2
    node.radial_roughness = 5.0f;      // Huang does not read it
    node.coat = -1.0f;                 // nor this
    const HuangParams p = mapped_huang(node);
    EXPECT_EQ(p.reflection, 0.0f);
    EXPECT_EQ(p.transmission, 0.5f);
    EXPECT_EQ(p.secondary_reflection, 3.0f);
    const Expected<HuangFiber> fiber = HuangFiber::create(p);
    ASSERT_TRUE(fiber.ok()) << fiber.error().message;
    EXPECT_DOUBLE_EQ(fiber.value().aspect_ratio(), 0.5);
    EXPECT_EQ(fiber.value().m_r(), 0.0);
}

TEST(PrincipledHairHuang, InvalidInputsAreRefusedByName) {
    const float nan = std::nanf("");
    const std::vector<std::pair<std::function<void(PrincipledHairNode &)>, std::string>> cases = {
        {[](PrincipledHairNode &n) { n.aspect_ratio = 0.0f; }, "aspect_ratio must be in (0, 1000]"},
        {[](PrincipledHairNode &n) { n.aspect_ratio = -0.5f; }, "aspect_ratio"},
        {[&](PrincipledHairNode &n) { n.aspect_ratio = nan; }, "aspect_ratio"},
        {[&](PrincipledHairNode &n) { n.transmission = nan; }, "transmission"},
        {[](PrincipledHairNode &n) { n.secondary_reflection = INFINITY; }, "secondary_reflection"},
        {[](PrincipledHairNode &n) {
             n.reflection = 0.0f;
             n.transmission = -1.0f;
             n.secondary_reflection = 0.0f;
         },
         "all <= 0: Cycles allocates no closure"},
        {[](PrincipledHairNode &n) { n.roughness = 1.5f; }, "roughness"},
        {[](PrincipledHairNode &n) { n.ior = 0.9f; }, "ior"},
        {[](PrincipledHairNode &n) { n.color.g = 0.0f; }, "color.g"},
    };
    for (const auto &[spoil, name] : cases) {
        PrincipledHairNode node;
        spoil(node);
        const Expected<HuangParams> params = to_huang_params(node);
        ASSERT_FALSE(params.ok()) << name;
        EXPECT_NE(params.error().message.find(name), std::string::npos)
            << "message '" << params.error().message << "' does not say " << name;
    }
}

}  // namespace
}  // namespace hairis
