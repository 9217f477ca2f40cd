// Table files as images, for the table-file tests: encode tables to EXR bytes, read the bytes'
// header and float RGBA pixels with OpenImageIO, change them, and write them back.
#pragma once

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

#include "tables/table_file.h"

namespace hairis::testing {

// The EXR bytes of tables that must encode (an empty vector and a test failure otherwise).
inline std::vector<unsigned char> encode(const TableSet &t) {
    auto bytes = encode_table_exr(t);
    EXPECT_TRUE(bytes.ok()) << (bytes.ok() ? "" : bytes.error().message);
    return bytes.ok() ? bytes.value() : std::vector<unsigned char>{};
}

// The header and the float RGBA pixels of EXR bytes, as OpenImageIO reads them.
struct Image {
    OIIO::ImageSpec spec;
    std::vector<float> px;
    float &at(int x, int y, int c) { return px[(size_t(y) * size_t(spec.width) + size_t(x)) * 4 + size_t(c)]; }
};

inline Image read_image(const std::vector<unsigned char> &bytes) {
    OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
    auto in = OIIO::ImageInput::create("openexr");
    Image image;
    OIIO::ImageSpec config;
    void *proxy_pointer = &reader;
    config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy_pointer);
    EXPECT_TRUE(in && in->open("t.exr", image.spec, config));
    image.px.resize(size_t(image.spec.width) * image.spec.height * image.spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, image.spec.nchannels, OIIO::TypeDesc::FLOAT, image.px.data()));
    in->close();
    return image;
}

inline std::vector<unsigned char> write_image(const Image &image) {
    std::vector<unsigned char> out_bytes;
    OIIO::Filesystem::IOVecOutput writer(out_bytes);
    auto out = OIIO::ImageOutput::create("openexr");
    EXPECT_TRUE(out->set_ioproxy(&writer));
    EXPECT_TRUE(out->open("t.exr", image.spec));
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, image.px.data()));
    EXPECT_TRUE(out->close());
    return out_bytes;
}

}  // namespace hairis::testing
