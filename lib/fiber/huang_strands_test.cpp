// HuangStrands: a hit with inputs is shaded with the fiber of the node with those inputs (made
// here from the node directly), a hit without with the node's own; it reads the inputs the
// node reads under its parametrization but Radial Roughness and Coat.
#include "fiber/huang_strands.h"

#include <gtest/gtest.h>

#include <cmath>

namespace hairis {
namespace {

PrincipledHairNode melanin_node() {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::Melanin;
    node.melanin = 0.5f;
    node.random_color = 0.4f;
    node.aspect_ratio = 0.8f;
    return node;
}

FiberHit hit_at(double theta_o) {
    FiberHit hit;
    hit.wo = {float(std::sin(theta_o)), 0.0f, float(-std::cos(theta_o))};
    hit.normal = {0.0f, 0.6f, 0.8f};
    return hit;
}

TEST(HuangStrands, AHitWithInputsIsTheFiberOfTheNodeWithThem) {
    const PrincipledHairNode node = melanin_node();
    const HuangStrands strands = HuangStrands::create(node).value();
    HairInputValues inputs;
    const float random = 0.9f, roughness = 0.5f;
    inputs.set(HairInput::Random, &random);
    inputs.set(HairInput::Roughness, &roughness);
    PrincipledHairNode strand_node = node;
    strand_node.random = random;
    strand_node.roughness = roughness;
    const HuangParams expected = to_huang_params(strand_node).value();
    ScratchBuffer scratch;
    const HuangFiber &fiber = strands.fiber_at(&inputs, scratch);
    EXPECT_EQ(fiber.params().roughness, expected.roughness);
    EXPECT_EQ(fiber.params().sigma_a.r, expected.sigma_a.r);
    EXPECT_EQ(fiber.params().sigma_a.b, expected.sigma_a.b);
    // Random Color moved the absorption away from the node's own.
    EXPECT_NE(fiber.params().sigma_a.r, strands.fiber()->params().sigma_a.r);
    // The prepared point is that fiber's Cycles closure.
    FiberHit hit = hit_at(0.4);
    hit.inputs = &inputs;
    const FiberPoint &point = strands.prepare(hit, scratch);
    ASSERT_NE(point.huang_point(), nullptr);
    const HuangFiber made = HuangFiber::create(expected).value();
    const Vec3 wi = safe_normalize(Vec3{-0.3f, 0.5f, 0.6f});
    EXPECT_EQ(point.huang_point()->f_reflection(wi).g, made.at(hit).f_reflection(wi).g);
}

// Cycles' bsdf_hair_huang_blur: the closure's roughness raised to Filter Glossy's, the rest of
// the strand's fiber kept; a blur below it leaves the fiber alone.
TEST(HuangStrands, FilterGlossyRaisesTheRoughnessOnly) {
    const PrincipledHairNode node = melanin_node();
    const HuangStrands strands = HuangStrands::create(node).value();
    ScratchBuffer scratch;
    const HuangFiber &own = *strands.fiber();
    ASSERT_LT(own.roughness(), 0.45);
    const HuangFiber &wide = strands.fiber_at(nullptr, scratch, 0.45f);
    EXPECT_FLOAT_EQ(float(wide.roughness()), 0.45f);
    EXPECT_EQ(wide.params().sigma_a.g, own.params().sigma_a.g);
    EXPECT_EQ(wide.params().ior, own.params().ior);
    EXPECT_EQ(&strands.fiber_at(nullptr, scratch, float(own.roughness()) * 0.5f), &own);
    FiberHit hit = hit_at(0.4);
    hit.blur_roughness = 0.45f;
    const FiberPoint &point = strands.prepare(hit, scratch);
    ASSERT_NE(point.huang_point(), nullptr);
    EXPECT_FLOAT_EQ(float(point.huang_point()->fiber().roughness()), 0.45f);
}

TEST(HuangStrands, AHitWithoutInputsIsTheNodesOwnFiber) {
    const HuangStrands strands = HuangStrands::create(melanin_node()).value();
    ScratchBuffer scratch;
    EXPECT_EQ(&strands.fiber_at(nullptr, scratch), strands.fiber().get());
    const HairInputValues none;
    EXPECT_EQ(&strands.fiber_at(&none, scratch), strands.fiber().get());
    EXPECT_EQ(strands.as_huang(), strands.fiber().get());
}

TEST(HuangStrands, ReadsWhatTheNodeReadsButRadialRoughnessAndCoat) {
    const HuangStrands strands = HuangStrands::create(melanin_node()).value();
    EXPECT_TRUE(strands.reads_input(HairInput::Melanin));
    EXPECT_TRUE(strands.reads_input(HairInput::RandomColor));
    EXPECT_TRUE(strands.reads_input(HairInput::Roughness));
    EXPECT_FALSE(strands.reads_input(HairInput::Color));  // Melanin Concentration hides it
    EXPECT_FALSE(strands.reads_input(HairInput::RadialRoughness));
    EXPECT_FALSE(strands.reads_input(HairInput::Coat));
    EXPECT_EQ(strands.strand_inputs(), &strands);
}

TEST(HuangStrands, RefusesANodeHuangRefuses) {
    PrincipledHairNode node = melanin_node();
    node.aspect_ratio = -1.0f;
    const Expected<HuangStrands> made = HuangStrands::create(node);
    ASSERT_FALSE(made);
    EXPECT_NE(made.error().message.find("aspect_ratio"), std::string::npos) << made.error().message;
}

}  // namespace
}  // namespace hairis
