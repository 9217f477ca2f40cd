#include "render/texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace hairis {
namespace {

// A 4 × 2 image whose texel (i, j) holds (i, j, 10) (linear) so lookups can be read back.
std::shared_ptr<const EnvironmentImage> ramp(ImageColorSpace space = ImageColorSpace::Linear) {
    std::vector<float> rgb;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 4; ++i) rgb.insert(rgb.end(), {float(i), float(j), 10.0f});
    return std::make_shared<const EnvironmentImage>(EnvironmentImage::create(4, 2, rgb, space).value());
}

ImageTexture texture(TextureExtension ext, TextureInterpolation interp = TextureInterpolation::Linear) {
    ImageTextureDesc d;
    d.image = ramp();
    d.extension = ext;
    d.interpolation = interp;
    return ImageTexture::create(d).value();
}

TEST(ImageTexture, TexelCentresReturnTheTexel) {
    const ImageTexture t = texture(TextureExtension::Repeat);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 4; ++i) {
            const Rgb c = t.lookup((i + 0.5f) / 4.0f, (j + 0.5f) / 2.0f);
            EXPECT_NEAR(c.r, i, 1e-5);
            EXPECT_NEAR(c.g, j, 1e-5);
            EXPECT_NEAR(c.b, 10.0f, 1e-5);
        }
}

TEST(ImageTexture, LinearBlendsBetweenCentres) {
    const ImageTexture t = texture(TextureExtension::Extend);
    // A quarter of the way from centre (1, 0) to centre (2, 0), 0.3 of the way up to row 1.
    const Rgb c = t.lookup((1.5f + 0.25f) / 4.0f, (0.5f + 0.3f) / 2.0f);
    EXPECT_NEAR(c.r, 1.25f, 1e-5);
    EXPECT_NEAR(c.g, 0.3f, 1e-5);
}

TEST(ImageTexture, ExtensionsOutsideTheUnitSquare) {
    // u = 0 is the left edge of the image: half-way between texels −1 and 0.
    const float u = 0.0f, v = 0.25f;  // v at the centre of row 0
    EXPECT_NEAR(texture(TextureExtension::Repeat).lookup(u, v).r, 0.5f * 3.0f + 0.5f * 0.0f, 1e-5);
    EXPECT_NEAR(texture(TextureExtension::Extend).lookup(u, v).r, 0.0f, 1e-5);
    EXPECT_NEAR(texture(TextureExtension::Mirror).lookup(u, v).r, 0.0f, 1e-5);  // texel −1 mirrors to 0
    // Clip: texel −1 is black, so half of texel 0's (0, 0, 10) remains.
    EXPECT_NEAR(texture(TextureExtension::Clip).lookup(u, v).b, 5.0f, 1e-5);
    EXPECT_NEAR(texture(TextureExtension::Clip).lookup(-0.5f, v).b, 0.0f, 1e-6);
    // Repeat with a period: u + 3 is u.
    const Rgb a = texture(TextureExtension::Repeat).lookup(0.3f, 0.6f);
    const Rgb b = texture(TextureExtension::Repeat).lookup(3.3f, -1.4f);
    EXPECT_NEAR(a.r, b.r, 1e-4);
    EXPECT_NEAR(a.g, b.g, 1e-4);
    // Mirror: u in [1, 2] reads the image backwards.
    EXPECT_NEAR(texture(TextureExtension::Mirror, TextureInterpolation::Closest).lookup(1.1f, 0.25f).r, 3.0f, 1e-6);
    EXPECT_NEAR(texture(TextureExtension::Mirror, TextureInterpolation::Closest).lookup(1.9f, 0.25f).r, 0.0f, 1e-6);
}

TEST(ImageTexture, ClosestReadsTheTexelUnderThePoint) {
    const ImageTexture t = texture(TextureExtension::Repeat, TextureInterpolation::Closest);
    EXPECT_EQ(t.lookup(0.49f, 0.1f).r, 1.0f);
    EXPECT_EQ(t.lookup(0.51f, 0.9f).r, 2.0f);
    EXPECT_EQ(t.lookup(0.51f, 0.9f).g, 1.0f);
}

TEST(ImageTexture, SrgbIsDecodedAfterInterpolation) {
    std::vector<float> rgb = {0.2f, 0.2f, 0.2f, 0.8f, 0.8f, 0.8f};
    ImageTextureDesc d;
    d.image = std::make_shared<const EnvironmentImage>(
        EnvironmentImage::create(2, 1, rgb, ImageColorSpace::Srgb).value());
    d.extension = TextureExtension::Extend;
    const ImageTexture t = ImageTexture::create(d).value();
    // Half-way between the centres: decode(0.5), not (decode(0.2) + decode(0.8)) / 2.
    const float expected = std::pow((0.5f + 0.055f) / 1.055f, 2.4f);
    EXPECT_NEAR(t.lookup(0.5f, 0.5f).r, expected, 1e-5);
}

TEST(ImageTexture, MappingNodeTypes) {
    ImageTextureDesc d;
    d.image = ramp();
    d.extension = TextureExtension::Extend;
    d.interpolation = TextureInterpolation::Closest;
    d.use_mapping = true;
    // Point: R·(s∘x) + t with a rotation of 90° about Z: (u, v) → (−s_y v, s_x u) + t.
    d.mapping.type = MappingType::Point;
    d.mapping.rotation = {0.0f, 0.0f, float(kHalfPi)};
    d.mapping.scale = {2.0f, 0.5f, 1.0f};
    d.mapping.location = {0.9f, 0.1f, 0.0f};
    const ImageTexture point = ImageTexture::create(d).value();
    const float u = 0.2f, v = 0.6f;
    const float x = -0.5f * v + 0.9f, y = 2.0f * u + 0.1f;
    EXPECT_EQ(point.lookup(u, v).r, point.lookup_mapped(x, y).r);
    EXPECT_EQ(point.lookup(u, v).g, point.lookup_mapped(x, y).g);
    // Texture: the inverse, Rᵀ(x − t)/s, so a Point and a Texture mapping of the same inputs
    // cancel.
    d.mapping.type = MappingType::Texture;
    const ImageTexture inverse = ImageTexture::create(d).value();
    const Rgb direct = inverse.lookup(x, y);
    const Rgb plain = texture(TextureExtension::Extend, TextureInterpolation::Closest).lookup(u, v);
    EXPECT_EQ(direct.r, plain.r);
    EXPECT_EQ(direct.g, plain.g);
    // Vector ignores the location.
    d.mapping.type = MappingType::Vector;
    const ImageTexture vector = ImageTexture::create(d).value();
    EXPECT_EQ(vector.lookup(u, v).r, point.lookup_mapped(x - 0.9f, y - 0.1f).r);
}

TEST(ImageTexture, RefusesWhatItCannotMap) {
    ImageTextureDesc d;
    EXPECT_FALSE(ImageTexture::create(d));  // no image
    d.image = ramp();
    d.use_mapping = true;
    d.mapping.type = MappingType::Normal;
    const auto normal = ImageTexture::create(d);
    ASSERT_FALSE(normal);
    EXPECT_NE(normal.error().message.find("Normal"), std::string::npos);
    d.mapping.type = MappingType::Point;
    d.mapping.scale = {1.0f, 0.0f, 1.0f};
    EXPECT_FALSE(ImageTexture::create(d));
    d.mapping.scale = {1.0f, 1.0f, 1.0f};
    d.mapping.location = {NAN, 0.0f, 0.0f};
    EXPECT_FALSE(ImageTexture::create(d));
}

TEST(ImageTexture, NonFiniteCoordinatesAreBlack) {
    const ImageTexture t = texture(TextureExtension::Repeat);
    EXPECT_EQ(t.lookup(NAN, 0.5f).b, 0.0f);
    EXPECT_EQ(t.lookup(INFINITY, 0.5f).b, 0.0f);
    // Huge but finite coordinates still wrap.
    EXPECT_GT(t.lookup(1e20f, 0.5f).b, 0.0f);
}

}  // namespace
}  // namespace hairis
