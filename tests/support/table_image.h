// Table files as images, with no test framework (the fuzz seed writer uses it too): read EXR
// bytes' header and float RGBA pixels with OpenImageIO, change them, rehash and write them back.
#pragma once

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/hash.h>
#include <OpenImageIO/imageio.h>

#include <cstddef>
#include <optional>
#include <vector>

namespace hairis::testing {

// The header and the float RGBA pixels of EXR bytes, as OpenImageIO reads them.
struct Image {
    OIIO::ImageSpec spec;
    std::vector<float> px;
    float &at(int x, int y, int c) { return px[(size_t(y) * size_t(spec.width) + size_t(x)) * 4 + size_t(c)]; }
};

// The image that EXR bytes hold, or nothing when OpenImageIO cannot read them.
inline std::optional<Image> decode_image(const std::vector<unsigned char> &bytes) {
    OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
    auto in = OIIO::ImageInput::create("openexr");
    Image image;
    OIIO::ImageSpec config;
    void *proxy_pointer = &reader;
    config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy_pointer);
    if (!in || !in->open("t.exr", image.spec, config)) return std::nullopt;
    image.px.resize(size_t(image.spec.width) * size_t(image.spec.height) * size_t(image.spec.nchannels));
    const bool read = in->read_image(0, 0, 0, image.spec.nchannels, OIIO::TypeDesc::FLOAT, image.px.data());
    in->close();
    if (!read) return std::nullopt;
    return image;
}

// The EXR bytes of an image, or nothing when OpenImageIO cannot write them.
inline std::optional<std::vector<unsigned char>> encode_image(const Image &image) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput writer(bytes);
    auto out = OIIO::ImageOutput::create("openexr");
    if (!out || !out->set_ioproxy(&writer) || !out->open("t.exr", image.spec) ||
        !out->write_image(OIIO::TypeDesc::FLOAT, image.px.data()) || !out->close())
        return std::nullopt;
    return bytes;
}

// Sets hairis:pixel_sha1 to the pixels' hash, as the encoder does, so that an edit of the
// pixels reaches the check it aims at rather than the hash check.
inline void rehash(Image &image) {
    OIIO::SHA1 sha(image.px.data(), image.px.size() * sizeof(float));
    image.spec.attribute("hairis:pixel_sha1", sha.digest());
}

}  // namespace hairis::testing
