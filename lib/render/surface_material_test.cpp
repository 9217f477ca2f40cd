#include "render/surface_material.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "fiber/fresnel.h"
#include "hemisphere.h"
#include "render/ggx_albedo.h"

namespace hairis {
namespace {

SurfaceMaterial material(std::vector<SurfaceNode> nodes) {
    Expected<SurfaceMaterial> m = SurfaceMaterial::create(std::move(nodes));
    EXPECT_TRUE(m) << (m ? "" : m.error().message);
    return std::move(m).value();
}

SurfaceBsdf at(const SurfaceMaterial &m, Vec3 wo, float u = 0.0f, float v = 0.0f) {
    return m.prepare({wo, Vec3{0, 0, 1}, Vec3{0, 0, 1}, u, v});
}

const SurfaceLobe *find(const SurfaceBsdf &b, SurfaceLobeKind kind, int skip = 0) {
    for (int i = 0; i < b.lobe_count(); ++i)
        if (b.lobe(i).kind == kind && skip-- == 0) return &b.lobe(i);
    return nullptr;
}

double albedo(const SurfaceBsdf &b, int channel = 1) {
    return testing::integrate_hemisphere([&](Vec3 wi) {
        float pdf;
        return double(b.eval(wi, pdf)[channel]);
    });
}

void expect_rgb(Rgb a, Rgb b, float tol) {
    EXPECT_NEAR(a.r, b.r, tol);
    EXPECT_NEAR(a.g, b.g, tol);
    EXPECT_NEAR(a.b, b.b, tol);
}

TEST(SurfaceMaterial, Principled34DefaultsMakeDiffuseAndSpecular) {
    PrincipledBsdfNode p;  // Blender 3.4's defaults: Specular 0.5, Roughness 0.5
    p.base_color.value = Rgb(0.6f, 0.4f, 0.2f);
    const SurfaceBsdf b = at(material({p}), testing::polar_direction(0.5, 0.0));
    ASSERT_EQ(b.lobe_count(), 2);
    const SurfaceLobe *diffuse = find(b, SurfaceLobeKind::PrincipledDiffuse);
    ASSERT_TRUE(diffuse);
    expect_rgb(diffuse->weight, Rgb(0.6f, 0.4f, 0.2f), 1e-6f);
    EXPECT_EQ(diffuse->roughness, 0.5f);
    const SurfaceLobe *spec = find(b, SurfaceLobeKind::Microfacet);
    ASSERT_TRUE(spec);
    // Specular 0.5: cspec0 = 0.08 · 0.5 = 0.04 and η = 2/(1 − sqrt(0.04)) − 1 = 1.5.
    expect_rgb(spec->f0, Rgb(0.04f), 1e-6f);
    EXPECT_NEAR(spec->ior, 1.5f, 1e-6f);
    EXPECT_EQ(spec->shadowing, MicrofacetShadowing::Separable);
    EXPECT_EQ(spec->fresnel, MicrofacetFresnel::Interpolated34);
    EXPECT_NEAR(spec->alpha, 0.25f, 1e-7f);
    expect_rgb(spec->weight, Rgb(1.0f), 0.0f);
}

TEST(SurfaceMaterial, Principled34MetallicTintSheenAndClearcoat) {
    PrincipledBsdfNode p;
    p.base_color.value = Rgb(0.9f, 0.5f, 0.1f);
    p.metallic = 0.25f;
    p.specular_tint = 1.0f;
    p.sheen = 0.5f;
    p.sheen_tint = 1.0f;
    p.coat = 0.8f;
    p.coat_roughness = 0.2f;
    const SurfaceBsdf b = at(material({p}), testing::polar_direction(0.3, 1.0));
    const SurfaceLobe *diffuse = find(b, SurfaceLobeKind::PrincipledDiffuse);
    ASSERT_TRUE(diffuse);
    expect_rgb(diffuse->weight, Rgb(0.9f, 0.5f, 0.1f) * 0.75f, 1e-6f);
    // Specular tint 1: cspec0 = 0.04 · base / lum(0.3, 0.6, 0.1) · 0.75 + 0.25 base.
    const Rgb base(0.9f, 0.5f, 0.1f);
    const float lum = 0.3f * 0.9f + 0.6f * 0.5f + 0.1f * 0.1f;
    const SurfaceLobe *spec = find(b, SurfaceLobeKind::Microfacet);
    ASSERT_TRUE(spec);
    expect_rgb(spec->f0, base / lum * 0.04f * 0.75f + base * 0.25f, 1e-6f);
    // Sheen tint 1: the base colour over its Rec.709 luminance.
    const SurfaceLobe *sheen = find(b, SurfaceLobeKind::Sheen34);
    ASSERT_TRUE(sheen);
    expect_rgb(sheen->weight, base / luminance(base) * 0.5f * 0.75f, 1e-5f);
    const SurfaceLobe *coat = find(b, SurfaceLobeKind::Microfacet, 1);
    ASSERT_TRUE(coat);
    EXPECT_EQ(coat->distribution, MicrofacetDistribution::Gtr1);
    EXPECT_NEAR(coat->alpha, 0.04f, 1e-7f);
    EXPECT_EQ(coat->shadowing_alpha2, 0.0625f);
    EXPECT_NEAR(coat->fresnel_scale, 0.2f, 1e-7f);
    expect_rgb(coat->f0, Rgb(0.04f), 0.0f);
    EXPECT_EQ(coat->sampling, MicrofacetSampling::Cycles34Clearcoat);
    // Selection weights: |mean weight| × the mean Fresnel at ω_o·n for the microfacets;
    // at the camera hit every lobe has at least 1/8 of their sum.
    const float mu = std::cos(0.3f);
    const float f0 = fresnel_dielectric(1.0f, 1.5f);
    const float s = (fresnel_dielectric(mu, 1.5f) - f0) / (1.0f - f0);
    EXPECT_NEAR(coat->select, (0.04f * (1.0f - s) + s) * 0.2f, 1e-6f);
    EXPECT_NEAR(diffuse->select, (0.9f + 0.5f + 0.1f) / 3.0f * 0.75f, 1e-6f);
    const SurfaceMaterial m = material({p});
    const SurfaceBsdf first = m.prepare({testing::polar_direction(0.3, 1.0), Vec3{0, 0, 1}, Vec3{0, 0, 1}, 0, 0, true});
    float total = 0.0f;
    for (int i = 0; i < b.lobe_count(); ++i) total += b.lobe(i).select;
    for (int i = 0; i < first.lobe_count(); ++i)
        EXPECT_NEAR(first.lobe(i).select, std::max(b.lobe(i).select, 0.125f * total), 1e-6f) << i;
    PrincipledBsdfNode later = p;  // Cycles 4.x has no defensive sampling
    later.cycles = CyclesVersion::V4_5;
    later.specular_tint = 0.0f;
    later.sheen = 0.0f;
    later.sheen_tint = 0.5f;
    const SurfaceMaterial m4 = material({later});
    const SurfaceBsdf a4 = m4.prepare({testing::polar_direction(0.3, 1.0), Vec3{0, 0, 1}, Vec3{0, 0, 1}, 0, 0, false});
    const SurfaceBsdf b4 = m4.prepare({testing::polar_direction(0.3, 1.0), Vec3{0, 0, 1}, Vec3{0, 0, 1}, 0, 0, true});
    for (int i = 0; i < a4.lobe_count(); ++i) EXPECT_EQ(a4.lobe(i).select, b4.lobe(i).select);
}

TEST(SurfaceMaterial, Principled4SpecularLayerDimsTheDiffuse) {
    PrincipledBsdfNode p;
    p.cycles = CyclesVersion::V4_5;
    p.ior = 1.5f;
    p.roughness = 0.4f;
    p.base_color.value = Rgb(0.5f, 0.7f, 0.9f);
    // ω_o on a node of the tables' μ axis, roughness on one of r: only z is interpolated.
    const float mu = 9.0f / 15.0f;
    const Vec3 wo{std::sqrt(1.0f - mu * mu), 0.0f, mu};
    const float r = 6.0f / 15.0f;
    p.roughness = r;
    const SurfaceBsdf b = at(material({p}), wo);
    const SurfaceLobe *spec = find(b, SurfaceLobeKind::Microfacet);
    ASSERT_TRUE(spec);
    EXPECT_EQ(spec->fresnel, MicrofacetFresnel::SchlickIor);
    EXPECT_EQ(spec->shadowing, MicrofacetShadowing::Correlated);
    EXPECT_TRUE(spec->below_ng_is_zero);
    EXPECT_NEAR(spec->ior, 1.5f, 1e-6f);
    expect_rgb(spec->f0, Rgb(0.04f), 1e-6f);
    EXPECT_EQ(spec->energy_scale, 1.0f);  // GGX, not Multiscatter GGX
    // The diffuse keeps 1 − (f0 + (1 − f0) s), s the Fresnel factor at (r, μ, z(1.5)), z
    // between the nodes 6 and 7 of the table's z axis.
    const double z = std::sqrt(0.5 / 2.5) * 15.0;
    const double t = z - 6.0;
    const double s = (1.0 - t) * ggx_fresnel_factor_ior(sqr(r), mu, GgxAlbedoTables::s_ior_of(6)) +
                     t * ggx_fresnel_factor_ior(sqr(r), mu, GgxAlbedoTables::s_ior_of(7));
    const double keep = 1.0 - (0.04 + 0.96 * s);
    const SurfaceLobe *diffuse = find(b, SurfaceLobeKind::Lambert);
    ASSERT_TRUE(diffuse);
    expect_rgb(diffuse->weight, Rgb(0.5f, 0.7f, 0.9f) * float(keep), 2e-5f);
}

TEST(SurfaceMaterial, Principled4IorLevelScalesF0) {
    PrincipledBsdfNode p;
    p.cycles = CyclesVersion::V4_5;
    p.ior = 1.5f;
    p.specular = 0.25f;  // IOR Level: F0 = 0.04 · 2 · 0.25
    const SurfaceBsdf b = at(material({p}), testing::polar_direction(0.4, 0.0));
    const SurfaceLobe *spec = find(b, SurfaceLobeKind::Microfacet);
    ASSERT_TRUE(spec);
    expect_rgb(spec->f0, Rgb(0.02f), 1e-6f);
    const float s = std::sqrt(0.02f);
    EXPECT_NEAR(spec->ior, (1.0f + s) / (1.0f - s), 1e-5f);
    p.specular = 0.0f;  // F0 = 0: η = 1, no specular lobe
    EXPECT_FALSE(find(at(material({p}), testing::polar_direction(0.4, 0.0)), SurfaceLobeKind::Microfacet));
}

TEST(SurfaceMaterial, MultiscatterGgxCompensatesItsLostEnergy) {
    // White furnace: a white Glossy BSDF and a white metal with Multiscatter GGX reflect ~1
    // (the table's interpolation is the only error).
    for (float roughness : {0.35f, 0.7f})
        for (double theta : {0.3, 1.2}) {
            GlossyBsdfNode g;
            g.cycles = CyclesVersion::V4_5;
            g.color.value = Rgb(1.0f);
            g.roughness = roughness;
            g.multiscatter = true;
            EXPECT_NEAR(albedo(at(material({g}), testing::polar_direction(theta, 0.0))), 1.0, 0.015)
                << roughness << " " << theta;
            PrincipledBsdfNode metal;
            metal.cycles = CyclesVersion::V4_5;
            metal.multiscatter = true;
            metal.metallic = 1.0f;
            metal.roughness = roughness;
            metal.base_color.value = Rgb(1.0f);
            EXPECT_NEAR(albedo(at(material({metal}), testing::polar_direction(theta, 0.0))), 1.0, 0.015);
            // Without it the lobe reflects the single-scattering albedo E.
            g.multiscatter = false;
            EXPECT_NEAR(albedo(at(material({g}), testing::polar_direction(theta, 0.0))),
                        ggx_reflection_albedo(double(roughness) * roughness, std::cos(theta)), 3e-3);
        }
}

TEST(SurfaceMaterial, Principled4WhiteDielectricNearlyConservesEnergy) {
    // Cycles' layering takes the specular's albedo estimate from the diffuse below it: a white
    // dielectric reflects about 1, never more than a little.
    for (double theta : {0.2, 0.8, 1.3}) {
        PrincipledBsdfNode p;
        p.cycles = CyclesVersion::V4_5;
        p.multiscatter = true;
        p.ior = 1.5f;
        p.base_color.value = Rgb(1.0f);
        const double a = albedo(at(material({p}), testing::polar_direction(theta, 0.0)));
        EXPECT_GT(a, 0.95) << theta;
        EXPECT_LT(a, 1.02) << theta;
    }
}

TEST(SurfaceMaterial, Principled4CoatAttenuatesAndTints) {
    PrincipledBsdfNode p;
    p.cycles = CyclesVersion::V4_5;
    p.base_color.value = Rgb(0.8f);
    p.specular = 0.0f;  // no specular layer: the coat alone dims the diffuse
    p.coat = 1.0f;
    p.coat_roughness = 0.2f;
    p.coat_ior = 1.5f;
    p.coat_tint = Rgb(0.5f, 1.0f, 1.0f);
    const float mu = 0.8f;
    const SurfaceBsdf b = at(material({p}), Vec3{0.6f, 0.0f, mu});
    const SurfaceLobe *coat = find(b, SurfaceLobeKind::Microfacet);
    ASSERT_TRUE(coat);
    EXPECT_EQ(coat->fresnel, MicrofacetFresnel::Dielectric);
    EXPECT_GT(coat->energy_scale, 1.0f);  // the coat always compensates
    const SurfaceLobe *diffuse = find(b, SurfaceLobeKind::Lambert);
    ASSERT_TRUE(diffuse);
    // Red goes through the tint along the refracted path: 0.5^(1/cos θ_t).
    const float cos_t = std::sqrt(1.0f - (1.0f - mu * mu) / (1.5f * 1.5f));
    EXPECT_NEAR(diffuse->weight.r / diffuse->weight.g, std::pow(0.5f, 1.0f / cos_t), 1e-5f);
    EXPECT_LT(diffuse->weight.g, 0.8f);
}

TEST(SurfaceMaterial, MixAndAddWeightTheirInputs) {
    DiffuseBsdfNode red, blue;
    red.color.value = Rgb(1.0f, 0.0f, 0.0f);
    blue.color.value = Rgb(0.0f, 0.0f, 1.0f);
    MixShaderNode mix;
    mix.factor = 0.25f;
    mix.first = 0;
    mix.second = 1;
    const SurfaceBsdf m = at(material({red, blue, mix}), testing::polar_direction(0.3, 0.0));
    ASSERT_EQ(m.lobe_count(), 2);
    expect_rgb(m.lobe(0).weight, Rgb(0.75f, 0.0f, 0.0f), 1e-7f);
    expect_rgb(m.lobe(1).weight, Rgb(0.0f, 0.0f, 0.25f), 1e-7f);
    AddShaderNode add;
    add.first = 0;
    add.second = 1;
    const SurfaceBsdf a = at(material({red, blue, add}), testing::polar_direction(0.3, 0.0));
    expect_rgb(a.lobe(0).weight, Rgb(1.0f, 0.0f, 0.0f), 0.0f);
    expect_rgb(a.lobe(1).weight, Rgb(0.0f, 0.0f, 1.0f), 0.0f);
    // The factor is clamped like Cycles' Mix Shader.
    mix.factor = 1.7f;
    EXPECT_EQ(at(material({red, blue, mix}), testing::polar_direction(0.3, 0.0)).lobe_count(), 1);
}

TEST(SurfaceMaterial, EmissionFollowsTheTree) {
    EmissionNode e;
    e.color = Rgb(1.0f, 0.5f, 0.25f);
    e.strength = 4.0f;
    PrincipledBsdfNode p;
    p.emission = Rgb(0.0f, 2.0f, 0.0f);
    MixShaderNode mix;
    mix.factor = 0.25f;
    mix.first = 0;
    mix.second = 1;
    AddShaderNode add;  // the emission once more on top
    add.first = 2;
    add.second = 0;
    const SurfaceMaterial m = material({e, p, mix, add});
    expect_rgb(m.emission(), Rgb(1.0f, 0.5f, 0.25f) * 4.0f * 1.75f + Rgb(0.0f, 2.0f, 0.0f) * 0.25f, 1e-5f);
    EXPECT_EQ(at(m, testing::polar_direction(0.2, 0.0)).lobe_count(), 2);  // emission makes no lobe
}

TEST(SurfaceMaterial, TextureFeedsTheBaseColour) {
    std::vector<float> rgb = {0.1f, 0.2f, 0.3f, 0.9f, 0.8f, 0.7f};
    ImageTextureDesc d;
    d.image = std::make_shared<const EnvironmentImage>(EnvironmentImage::create(2, 1, rgb).value());
    d.interpolation = TextureInterpolation::Closest;
    auto texture = std::make_shared<const ImageTexture>(ImageTexture::create(d).value());
    for (CyclesVersion version : {CyclesVersion::V3_4, CyclesVersion::V4_5}) {
        PrincipledBsdfNode p;
        p.cycles = version;
        p.specular = version == CyclesVersion::V3_4 ? 0.0f : 0.5f;
        if (version == CyclesVersion::V4_5) p.ior = 1.0f;  // η = 1: no specular layer
        p.base_color.texture = texture;
        const SurfaceMaterial m = material({p});
        const SurfaceBsdf left = at(m, testing::polar_direction(0.4, 0.0), 0.25f, 0.5f);
        const SurfaceBsdf right = at(m, testing::polar_direction(0.4, 0.0), 0.75f, 0.5f);
        ASSERT_EQ(left.lobe_count(), 1);
        expect_rgb(left.lobe(0).weight, Rgb(0.1f, 0.2f, 0.3f), 1e-6f);
        expect_rgb(right.lobe(0).weight, Rgb(0.9f, 0.8f, 0.7f), 1e-6f);
    }
}

TEST(SurfaceMaterial, Cycles34LiftsTheNormalForGrazingReflections) {
    // A smooth normal tilted away from a grazing view: its mirror reflection goes below the
    // face; 3.4 raises the normal until the reflection makes min(0.9 ω_o·ng, 0.01) with ng.
    const Vec3 ng{0, 0, 1};
    const Vec3 n = safe_normalize(Vec3{0.4f, 0.0f, 1.0f});
    const Vec3 wo = safe_normalize(Vec3{-1.0f, 0.0f, 0.15f});
    const Vec3 lifted = valid_reflection_normal(ng, wo, n);
    const Vec3 r = lifted * (2.0f * dot(lifted, wo)) - wo;
    EXPECT_NEAR(dot(r, ng), std::min(0.9f * dot(wo, ng), 0.01f), 1e-4f);
    EXPECT_NEAR(length(lifted), 1.0f, 1e-6f);
    EXPECT_NEAR(lifted.y, 0.0f, 1e-6f);  // in the plane of n and ng
    EXPECT_GT(dot(lifted, ng), dot(n, ng));
    // A normal whose reflection stays above is kept.
    const Vec3 head_on = safe_normalize(Vec3{0.3f, 0.0f, 1.0f});
    const Vec3 kept = valid_reflection_normal(ng, head_on, n);
    EXPECT_EQ(kept.x, n.x);
    EXPECT_EQ(kept.z, n.z);
    // Materials: 3.4 shades with the lifted normal, 4.x with the normal as given.
    DiffuseBsdfNode d;
    const SurfaceBsdf b34 = material({d}).prepare({wo, n, ng, 0, 0});
    EXPECT_NEAR(b34.normal().z, lifted.z, 1e-6f);
    d.cycles = CyclesVersion::V4_5;
    const SurfaceBsdf b4 = material({d}).prepare({wo, n, ng, 0, 0});
    EXPECT_NEAR(b4.normal().z, n.z, 1e-6f);
}

TEST(SurfaceMaterial, RefusesMalformedTrees) {
    DiffuseBsdfNode d;
    MixShaderNode mix;
    mix.first = 0;
    mix.second = 1;  // itself
    auto e = SurfaceMaterial::create({d, mix});
    ASSERT_FALSE(e);
    EXPECT_NE(e.error().message.find("Mix Shader"), std::string::npos) << e.error().message;
    EXPECT_FALSE(SurfaceMaterial::create({}));
    DiffuseBsdfNode later = d;
    later.cycles = CyclesVersion::V4_5;
    AddShaderNode add;
    add.first = 0;
    add.second = 1;
    auto versions = SurfaceMaterial::create({d, later, add});
    ASSERT_FALSE(versions);
    EXPECT_NE(versions.error().message.find("same Cycles"), std::string::npos);
    PrincipledBsdfNode bad;
    bad.roughness = NAN;
    auto nan = SurfaceMaterial::create({bad});
    ASSERT_FALSE(nan);
    EXPECT_NE(nan.error().message.find("roughness"), std::string::npos);
    // Four Principled 3.4 nodes (4 lobes each) under Add Shaders fill 16 lobes; five do not fit.
    PrincipledBsdfNode p;
    std::vector<SurfaceNode> nodes = {p, p, AddShaderNode{0, 1}, p, AddShaderNode{2, 3}, p, AddShaderNode{4, 5}};
    EXPECT_TRUE(SurfaceMaterial::create(nodes));
    nodes.push_back(p);
    nodes.push_back(AddShaderNode{6, 7});
    auto full = SurfaceMaterial::create(nodes);
    ASSERT_FALSE(full);
    EXPECT_NE(full.error().message.find("20 BSDF lobes"), std::string::npos) << full.error().message;
}

}  // namespace
}  // namespace hairis
