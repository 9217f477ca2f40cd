#include "fiber/fiber_spec.h"

#include <gtest/gtest.h>

namespace hairis {
namespace {

TEST(FiberSpec, Presets) {
    auto b = FiberSpec::preset("blonde");
    ASSERT_TRUE(b.ok());
    EXPECT_EQ(b.value().kind, FiberKind::Marschner);
    EXPECT_FLOAT_EQ(b.value().marschner.sigma_a.r, 0.15f);
    auto d = FiberSpec::preset("cycles-default");
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d.value().kind, FiberKind::Chiang);
    auto bad = FiberSpec::preset("ginger");
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.error().message.find("blonde, brunette, cycles-default"), std::string::npos);
}

TEST(FiberSpec, ParsesAParameterFile) {
    const auto spec = parse_fiber_spec(
        "# a dark fiber\nmodel = chiang\nparametrization = melanin\nmelanin = 0.5  # half\n"
        "tint = 1, 0.9, 0.8\nroughness=0.25\noffset_deg = 3\n");
    ASSERT_TRUE(spec.ok()) << spec.error().message;
    const FiberSpec &s = spec.value();
    EXPECT_EQ(s.node.parametrization, HairParametrization::Melanin);
    EXPECT_FLOAT_EQ(s.node.melanin, 0.5f);
    EXPECT_FLOAT_EQ(s.node.tint.b, 0.8f);
    EXPECT_FLOAT_EQ(s.node.roughness, 0.25f);
    EXPECT_NEAR(s.node.offset, radians(3.0), 1e-7);
    EXPECT_TRUE(s.create_model().ok());
    const auto params = s.parameters();
    ASSERT_TRUE(params.ok());
    EXPECT_EQ(params.value().front().first, "sigma_a.r");
}

TEST(FiberSpec, MarschnerKeys) {
    const auto spec = parse_fiber_spec("preset = brunette\neccentricity = 1\nbeta_r_deg = 5\n");
    ASSERT_TRUE(spec.ok()) << spec.error().message;
    EXPECT_EQ(spec.value().kind, FiberKind::Marschner);
    EXPECT_DOUBLE_EQ(spec.value().marschner.eccentricity, 1.0);
    EXPECT_NEAR(spec.value().marschner.beta_r, radians(5.0), 1e-12);
    auto model = spec.value().create_model();
    ASSERT_TRUE(model.ok());
    EXPECT_EQ(model.value()->name(), "marschner2003");
}

TEST(FiberSpec, ErrorsNameLineAndKey) {
    auto s = parse_fiber_spec("model = chiang\nroughness = lots\n");
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("line 2: roughness must be a finite number"), std::string::npos) << s.error().message;
    s = parse_fiber_spec("shinyness = 3\n");
    EXPECT_NE(s.error().message.find("unknown parameter \"shinyness\""), std::string::npos);
    s = parse_fiber_spec("color = 1 2\n");
    EXPECT_NE(s.error().message.find("three finite numbers"), std::string::npos);
    s = parse_fiber_spec("just words\n");
    EXPECT_NE(s.error().message.find("expected key = value"), std::string::npos);
    s = parse_fiber_spec("model = lambert\n");
    EXPECT_NE(s.error().message.find("model must be chiang, huang or marschner"), std::string::npos);
    // Values are checked when the model is built, with the model's own message.
    s = parse_fiber_spec("ior = 0.9\n");
    ASSERT_TRUE(s.ok());
    const auto m = s.value().create_model();
    ASSERT_FALSE(m.ok());
    EXPECT_NE(m.error().message.find("ior"), std::string::npos) << m.error().message;
}

TEST(FiberSpec, EqualScatteringGivesEqualParameters) {
    // The same σ_a through two parametrizations gives the same table parameters.
    FiberSpec a = FiberSpec::preset("cycles-default").value();
    auto mapped = to_chiang_params(a.node).value();
    FiberSpec b = a;
    b.node.parametrization = HairParametrization::AbsorptionCoefficient;
    b.node.absorption_coefficient = mapped.sigma_a;
    EXPECT_EQ(a.parameters().value(), b.parameters().value());
}

TEST(FiberSpec, HuangKeys) {
    const auto spec = parse_fiber_spec(
        "model = huang\nparametrization = absorption\nabsorption = 0.1, 0.2, 0.3\naspect_ratio = 0.5\n"
        "reflection = 1\ntransmission = 0.5\nsecondary_reflection = 0.2\nroughness = 0.4\noffset_deg = -3\n");
    ASSERT_TRUE(spec.ok()) << spec.error().message;
    EXPECT_EQ(spec.value().kind, FiberKind::Huang);
    auto model = spec.value().create_model();
    ASSERT_TRUE(model.ok()) << model.error().message;
    EXPECT_EQ(model.value()->name(), "huang2022");
    const auto *huang = dynamic_cast<const HuangFiber *>(model.value().get());
    ASSERT_NE(huang, nullptr);
    EXPECT_DOUBLE_EQ(huang->aspect_ratio(), 0.5);
    EXPECT_DOUBLE_EQ(huang->m_tt(), 0.5);
    EXPECT_NEAR(huang->m_trt(), 0.2, 1e-7);
    EXPECT_NEAR(huang->roughness(), 0.4, 1e-7);
    EXPECT_NEAR(huang->tilt(), radians(3.0), 1e-7);
    EXPECT_NEAR(huang->sigma()[2], 0.3, 1e-7);

    // options() names the Huang inputs and none of Chiang's, and reads back to the same fiber.
    const std::string options = spec.value().options();
    for (const char *name : {"model=huang", "aspect_ratio=0.5", "transmission=0.5", "secondary_reflection=0.2"})
        EXPECT_NE(options.find(name), std::string::npos) << name << " in " << options;
    for (const char *name : {"radial_roughness", "coat", "cycles"})
        EXPECT_EQ(options.find(name), std::string::npos) << name << " in " << options;
    std::string text = options;
    for (char &c : text)
        if (c == ';') c = '\n';
    const auto back = parse_fiber_spec(text);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back.value().parameters().value(), spec.value().parameters().value());
    EXPECT_EQ(spec.value().parameters().value().front().first, "sigma_a_r");
}

TEST(FiberSpec, HuangPresetAndParameters) {
    auto preset = FiberSpec::preset("cycles-default-huang");
    ASSERT_TRUE(preset.ok());
    EXPECT_EQ(preset.value().kind, FiberKind::Huang);
    const auto model = preset.value().create_model();
    ASSERT_TRUE(model.ok());
    EXPECT_NEAR(dynamic_cast<const HuangFiber &>(*model.value()).aspect_ratio(), 0.85, 1e-7);
    // Inputs Huang does not read leave its parameters alone; Roughness changes its colour.
    FiberSpec other = preset.value();
    other.node.radial_roughness = 0.9f;
    other.node.coat = 0.5f;
    EXPECT_EQ(other.parameters().value(), preset.value().parameters().value());
    other.node.roughness = 0.5f;
    EXPECT_NE(other.parameters().value()[0], preset.value().parameters().value()[0]);
    // A Huang node that cannot scatter is refused with Cycles' reason.
    FiberSpec dark = preset.value();
    dark.node.reflection = dark.node.transmission = dark.node.secondary_reflection = 0.0f;
    ASSERT_FALSE(dark.create_model().ok());
    EXPECT_NE(dark.create_model().error().message.find("no closure"), std::string::npos);
}

}  // namespace
}  // namespace hairis
