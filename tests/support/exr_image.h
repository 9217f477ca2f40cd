// Table files as images, for the table-file tests: encode tables to EXR bytes, read them as
// images (table_image.h), write them back, and expect the reader to refuse them.
#pragma once

#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "table_image.h"
#include "tables/table_file.h"

namespace hairis::testing {

// The EXR bytes of tables that must encode (an empty vector and a test failure otherwise).
inline std::vector<unsigned char> encode(const TableSet &t) {
    auto bytes = encode_table_exr(t);
    EXPECT_TRUE(bytes.ok()) << (bytes.ok() ? "" : bytes.error().message);
    return bytes.ok() ? bytes.value() : std::vector<unsigned char>{};
}

// The image of EXR bytes that must read (a test failure otherwise).
inline Image read_image(const std::vector<unsigned char> &bytes) {
    std::optional<Image> image = decode_image(bytes);
    EXPECT_TRUE(image) << "OpenImageIO cannot read the table file";
    return image ? std::move(*image) : Image{};
}

// The EXR bytes of an image that must write (a test failure otherwise).
inline std::vector<unsigned char> write_image(const Image &image) {
    std::optional<std::vector<unsigned char>> bytes = encode_image(image);
    EXPECT_TRUE(bytes) << "OpenImageIO cannot write the table file";
    return bytes ? std::move(*bytes) : std::vector<unsigned char>{};
}

// Expects the reader to refuse `bytes` as an invalid table with a message naming `fragment`.
inline void expect_refused(const std::vector<unsigned char> &bytes, const std::string &fragment) {
    const Expected<TableSet> t = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_FALSE(t.ok()) << "expected a refusal mentioning \"" << fragment << "\"";
    EXPECT_NE(t.error().message.find(fragment), std::string::npos) << t.error().message;
    EXPECT_EQ(t.error().kind, ErrorKind::InvalidTable) << t.error().message;
}

}  // namespace hairis::testing
