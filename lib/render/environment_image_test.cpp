#include "render/environment_image.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <string>
#include <vector>

namespace hairis {
namespace {

namespace fs = std::filesystem;

void expect_mentions(const std::string &message, const std::string &needle) {
    EXPECT_NE(message.find(needle), std::string::npos)
        << "\"" << message << "\" does not mention \"" << needle << "\"";
}

class EnvironmentImageFiles : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("hairis_environment_image_test_" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string &name) const { return (dir_ / name).string(); }

    // Writes `channels` floats per pixel with OpenImageIO itself, top row first as files
    // store them: an independent check of the loader's orientation and channel rules.
    void write_top_first(const std::string &file, int w, int h, int channels,
                         const std::vector<float> &data, OIIO::TypeDesc format = OIIO::TypeDesc::FLOAT) {
        auto out = OIIO::ImageOutput::create(file);
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(w, h, channels, format);
        if (channels == 4 || channels == 2) spec.alpha_channel = channels - 1;
        ASSERT_TRUE(out->open(file, spec)) << out->geterror();
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, data.data())) << out->geterror();
        ASSERT_TRUE(out->close());
    }

    std::string load_error(const std::string &file) {
        auto image = load_environment_image(file);
        return image.ok() ? "(no error)" : image.error().message;
    }

    fs::path dir_;
};

TEST_F(EnvironmentImageFiles, TopRowOfTheFileIsTheLastRow) {
    // 3 × 2, written top row first: the top row is (1, 2, 3) in R, the bottom row 10, 20, 30.
    const std::vector<float> top_first = {1, 0, 0, 2, 0, 0, 3, 0, 0, 10, 0, 0, 20, 0, 0, 30, 0, 0};
    write_top_first(path("a.exr"), 3, 2, 3, top_first);
    auto image = load_environment_image(path("a.exr"));
    ASSERT_TRUE(image.ok()) << image.error().message;
    EXPECT_FALSE(image.value().srgb());
    EXPECT_EQ(image.value().texel(0, 1).r, 1.0f);  // row 1 = top
    EXPECT_EQ(image.value().texel(2, 1).r, 3.0f);
    EXPECT_EQ(image.value().texel(0, 0).r, 10.0f);
    EXPECT_EQ(image.value().texel(2, 0).r, 30.0f);
}

TEST_F(EnvironmentImageFiles, WriterRoundTrips) {
    std::vector<float> rgb;
    for (int k = 0; k < 5 * 3; ++k) rgb.insert(rgb.end(), {0.5f + k, 2.0f * k, 100.0f / (k + 1)});
    auto image = EnvironmentImage::create(5, 3, rgb);
    ASSERT_TRUE(image.ok());
    for (const char *ext : {".exr", ".hdr"}) {
        ASSERT_FALSE(write_environment_image(path(std::string("w") + ext), image.value())) << ext;
        auto back = load_environment_image(path(std::string("w") + ext));
        ASSERT_TRUE(back.ok()) << back.error().message;
        ASSERT_EQ(back.value().width(), 5);
        ASSERT_EQ(back.value().height(), 3);
        // EXR is exact; RGBE keeps 8 bits of mantissa relative to the pixel's largest channel.
        const float tol = std::string(ext) == ".exr" ? 0.0f : 1.0f / 128.0f;
        for (size_t k = 0; k < rgb.size(); ++k) {
            const size_t p = k / 3 * 3;
            const float largest = std::max({rgb[p], rgb[p + 1], rgb[p + 2]});
            EXPECT_NEAR(back.value().rgb()[k], rgb[k], tol * largest) << ext << " " << k;
        }
    }
    // The writer reports what it cannot do.
    EXPECT_TRUE(write_rgb_image(path("x.exr"), 2, 2, {1, 2, 3}));
    EXPECT_TRUE(write_rgb_image(path("x.unknown-format"), 1, 1, {1, 2, 3}));
}

// The layout tests/blender/hdri.py writes: a Radiance header and flat (not run-length
// encoded) RGBE pixels, top row first.
TEST_F(EnvironmentImageFiles, FlatRadianceFile) {
    std::ofstream f(path("flat.hdr"), std::ios::binary);
    f << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n";
    // RGBE: value = mantissa · 2^(e − 136). (128, 64, 0, 129) = (1, 0.5, 0); (192, 0, 0, 131)
    // = 6; (128, 128, 128, 128) = 0.5 each; zero bytes = black.
    const unsigned char bytes[] = {128, 64, 0, 129, 192, 0, 0, 131, 128, 128, 128, 128, 0, 0, 0, 0};
    f.write(reinterpret_cast<const char *>(bytes), sizeof bytes);
    f.close();
    auto image = load_environment_image(path("flat.hdr"));
    ASSERT_TRUE(image.ok()) << image.error().message;
    const EnvironmentImage &im = image.value();
    EXPECT_FLOAT_EQ(im.texel(0, 1).r, 1.0f);  // top left
    EXPECT_FLOAT_EQ(im.texel(0, 1).g, 0.5f);
    EXPECT_FLOAT_EQ(im.texel(1, 1).r, 6.0f);
    EXPECT_FLOAT_EQ(im.texel(0, 0).b, 0.5f);
    EXPECT_EQ(im.texel(1, 0).r, 0.0f);
}

TEST_F(EnvironmentImageFiles, ChannelRules) {
    // Grey: to R, G and B.
    write_top_first(path("grey.exr"), 2, 1, 1, {0.25f, 4.0f});
    auto grey = load_environment_image(path("grey.exr"));
    ASSERT_TRUE(grey.ok()) << grey.error().message;
    EXPECT_EQ(grey.value().texel(1, 0).r, 4.0f);
    EXPECT_EQ(grey.value().texel(1, 0).g, 4.0f);
    EXPECT_EQ(grey.value().texel(1, 0).b, 4.0f);
    // Grey and alpha: grey to RGB, alpha ignored.
    write_top_first(path("ya.exr"), 1, 1, 2, {0.75f, 0.5f});
    auto ya = load_environment_image(path("ya.exr"));
    ASSERT_TRUE(ya.ok()) << ya.error().message;
    EXPECT_EQ(ya.value().texel(0, 0).b, 0.75f);
    // RGBA EXR (associated alpha): RGB as stored.
    write_top_first(path("rgba.exr"), 1, 1, 4, {0.5f, 1.5f, 2.5f, 0.25f});
    auto rgba = load_environment_image(path("rgba.exr"));
    ASSERT_TRUE(rgba.ok()) << rgba.error().message;
    EXPECT_EQ(rgba.value().texel(0, 0).r, 0.5f);
    EXPECT_EQ(rgba.value().texel(0, 0).b, 2.5f);
    // A PNG stores straight alpha; RGB comes back premultiplied, as Cycles associates it.
    // OpenImageIO writes the associated (0.4, 0.4, 0.4, 0.5) as straight (0.8, …, 0.5).
    write_top_first(path("rgba.png"), 1, 1, 4, {0.4f, 0.4f, 0.4f, 0.5f}, OIIO::TypeDesc::UINT8);
    auto png = load_environment_image(path("rgba.png"));
    ASSERT_TRUE(png.ok()) << png.error().message;
    EXPECT_TRUE(png.value().srgb());  // an 8-bit file under Auto
    EXPECT_NEAR(png.value().texel(0, 0).r, 0.4f, 2.0f / 255.0f);
}

TEST_F(EnvironmentImageFiles, ColorSpaces) {
    write_top_first(path("byte.png"), 1, 1, 3, {0.5f, 0.5f, 0.5f}, OIIO::TypeDesc::UINT8);
    auto automatic = load_environment_image(path("byte.png"));
    auto linear = load_environment_image(path("byte.png"), ImageColorSpace::Linear);
    ASSERT_TRUE(automatic.ok() && linear.ok());
    EXPECT_TRUE(automatic.value().srgb());
    EXPECT_FALSE(linear.value().srgb());
    // Stored encoded either way: 128/255.
    EXPECT_FLOAT_EQ(automatic.value().texel(0, 0).r, 128.0f / 255.0f);
    EXPECT_FLOAT_EQ(linear.value().texel(0, 0).r, 128.0f / 255.0f);
    write_top_first(path("float.exr"), 1, 1, 3, {0.5f, 0.5f, 0.5f});
    auto f = load_environment_image(path("float.exr"));
    ASSERT_TRUE(f.ok());
    EXPECT_FALSE(f.value().srgb());
    auto forced = load_environment_image(path("float.exr"), ImageColorSpace::Srgb);
    ASSERT_TRUE(forced.ok());
    EXPECT_TRUE(forced.value().srgb());
}

TEST(EnvironmentImageColor, SrgbCurve) {
    EXPECT_EQ(srgb_to_linear(0.0f), 0.0f);
    EXPECT_EQ(srgb_to_linear(-0.5f), 0.0f);
    EXPECT_FLOAT_EQ(srgb_to_linear(1.0f), 1.0f);
    EXPECT_FLOAT_EQ(srgb_to_linear(0.04f), 0.04f / 12.92f);
    // ((0.5 + 0.055) / 1.055)^2.4
    EXPECT_NEAR(srgb_to_linear(0.5f), 0.21404114f, 1e-6f);
}

TEST_F(EnvironmentImageFiles, BadFiles) {
    expect_mentions(load_error(path("missing.exr")), "file not found");
    expect_mentions(load_error(path("missing.exr")), "missing.exr");
    expect_mentions(load_error(dir_.string()), "is a directory");
    expect_mentions(load_error(""), "no file name");
    {
        std::ofstream(path("garbage.exr"), std::ios::binary) << "this is not an image at all";
    }
    expect_mentions(load_error(path("garbage.exr")), "not a readable image");
    // A valid EXR cut short: the header reads, the pixels do not.
    std::vector<float> big(64 * 64 * 3, 1.0f);
    for (size_t k = 0; k < big.size(); ++k) big[k] = float(k % 97);
    ASSERT_FALSE(write_rgb_image(path("full.exr"), 64, 64, big));
    const auto size = fs::file_size(path("full.exr"));
    fs::copy_file(path("full.exr"), path("cut.exr"));
    fs::resize_file(path("cut.exr"), size / 2);
    const std::string cut = load_error(path("cut.exr"));
    expect_mentions(cut, "\"" + path("cut.exr") + "\"");
    expect_mentions(cut, "the pixels cannot be read");
    // An absurd size in the header is refused before anything is read or allocated.
    {
        std::ofstream(path("huge.hdr"), std::ios::binary)
            << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 200000\n";
    }
    expect_mentions(load_error(path("huge.hdr")),
                    "image width must be an integer in [1, 65536] (got 200000)");
    {
        std::ofstream(path("big.hdr"), std::ios::binary)
            << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 60000\n";
    }
    expect_mentions(load_error(path("big.hdr")), "larger than the limit");
}

TEST_F(EnvironmentImageFiles, BadPixelsInFiles) {
    // 2 × 2, the NaN in the top-right pixel's G.
    std::vector<float> rgb(12, 1.0f);
    rgb[(1 * 2 + 1) * 3 + 1] = NAN;  // stored bottom row first: row 1 is the top
    ASSERT_FALSE(write_rgb_image(path("nan.exr"), 2, 2, rgb));
    const std::string nan = load_error(path("nan.exr"));
    expect_mentions(nan, "pixel (1, 0) (x from the left, y from the top) has G = nan");
    rgb[(1 * 2 + 1) * 3 + 1] = 1.0f;
    rgb[0] = -2.0f;  // bottom-left R
    ASSERT_FALSE(write_rgb_image(path("neg.exr"), 2, 2, rgb));
    const std::string neg = load_error(path("neg.exr"));
    expect_mentions(neg, "pixel (0, 1)");
    expect_mentions(neg, "R = -2");
    expect_mentions(neg, "must be finite and >= 0");
}

TEST(EnvironmentImagePixels, BlenderPixelArray) {
    // Blender's image.pixels: RGBA floats, bottom row first. 2 × 2.
    const std::vector<float> rgba = {1, 2, 3, 1, 4, 5, 6, 1, 7, 8, 9, 1, 10, 11, 12, 0.5f};
    auto image = EnvironmentImage::from_pixels(rgba.data(), (long long)rgba.size(), 2, 2, 4,
                                               ImageColorSpace::Linear);
    ASSERT_TRUE(image.ok()) << image.error().message;
    EXPECT_EQ(image.value().texel(1, 0).g, 5.0f);
    EXPECT_EQ(image.value().texel(0, 1).b, 9.0f);
    EXPECT_EQ(image.value().texel(1, 1).r, 10.0f);  // alpha ignored
    auto top = EnvironmentImage::from_pixels(rgba.data(), (long long)rgba.size(), 2, 2, 4,
                                             ImageColorSpace::Srgb, RowOrder::TopFirst);
    ASSERT_TRUE(top.ok());
    EXPECT_TRUE(top.value().srgb());
    EXPECT_EQ(top.value().texel(0, 1).r, 1.0f);  // the first row given is the top
    const std::vector<float> grey = {0.5f, 2.0f};
    auto g = EnvironmentImage::from_pixels(grey.data(), 2, 2, 1, 1, ImageColorSpace::Linear);
    ASSERT_TRUE(g.ok());
    EXPECT_EQ(g.value().texel(1, 0).b, 2.0f);
}

TEST(EnvironmentImagePixels, BadArrays) {
    auto error = [](Expected<EnvironmentImage> e) {
        return e.ok() ? std::string("(no error)") : e.error().message;
    };
    const std::vector<float> px(16, 1.0f);
    const auto linear = ImageColorSpace::Linear;
    expect_mentions(error(EnvironmentImage::from_pixels(px.data(), 15, 2, 2, 4, linear)),
                    "needs 16 floats (got 15)");
    expect_mentions(error(EnvironmentImage::from_pixels(px.data(), 16, 2, 2, 4, ImageColorSpace::Auto)),
                    "colour space");
    expect_mentions(error(EnvironmentImage::from_pixels(nullptr, 16, 2, 2, 4, linear)), "null");
    expect_mentions(error(EnvironmentImage::from_pixels(px.data(), 16, 2, 2, 0, linear)),
                    "image channels");
    // 65536 × 65536 × 4 floats would be 64 GiB: refused before anything is allocated.
    expect_mentions(error(EnvironmentImage::from_pixels(nullptr, 65536ll * 65536 * 4, 65536, 65536,
                                                        4, linear)),
                    "larger than the limit");
    expect_mentions(error(EnvironmentImage::create(0, 4, {})),
                    "image width must be an integer in [1, 65536] (got 0)");
    expect_mentions(error(EnvironmentImage::create(2, 1, {1, 2, 3})), "needs 6 RGB floats (got 3)");
    expect_mentions(error(EnvironmentImage::create(2, 1, {1, 2, 3, 4, INFINITY, 6})),
                    "pixel (1, 0) (x from the left, y from the top) has G = inf");
    expect_mentions(error(EnvironmentImage::create(1, 1, {1, 2, 3}, ImageColorSpace::Auto)), "Auto");
}

}  // namespace
}  // namespace hairis
