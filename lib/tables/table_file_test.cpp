#include "tables/table_file.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/hash.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include "core/math.h"

namespace hairis {
namespace {

TableSet small_tables(int theta_r_count = 3) {
    TableSet t;
    t.model = "chiang2016";
    t.source = "exact";
    t.parameters = {{"ior", 1.55}, {"roughness", 0.3}, {"sigma_a.r", 0.245531}};
    for (int r = 0; r < theta_r_count; ++r)
        t.theta_r_nodes.push_back(float(-kHalfPi + kPi * r / (theta_r_count - 1)));
    t.theta_i_count = 6;
    t.phi_count = 10;
    t.n_h_values = {1, 2, 4};
    for (int r = 0; r < theta_r_count; ++r)
        for (int i = 0; i < t.theta_i_count; ++i)
            for (int j = 0; j < t.phi_count; ++j)
                t.direct.push_back(float(1 + r) * std::exp(-0.1f * float(i * j)) / 3.0f);
    for (int r = 0; r < theta_r_count; ++r)
        for (int k = 0; k < 3; ++k)
            for (int i = 0; i < t.theta_i_count; ++i)
                t.multiple.push_back(0.01f * float(i + 1) / float(k + 1) + 1e-7f * float(r));
    return t;
}

std::vector<unsigned char> encode(const TableSet &t) {
    auto bytes = encode_table_exr(t);
    EXPECT_TRUE(bytes.ok()) << (bytes.ok() ? "" : bytes.error().message);
    return bytes.ok() ? bytes.value() : std::vector<unsigned char>{};
}

// Re-encodes valid table bytes after letting `edit` change the header or the pixels, the way
// a foreign or damaged writer would.
std::vector<unsigned char> tamper(const std::vector<unsigned char> &valid,
                                  const std::function<void(OIIO::ImageSpec &, std::vector<float> &)> &edit) {
    OIIO::Filesystem::IOMemReader reader(valid.data(), valid.size());
    auto in = OIIO::ImageInput::create("openexr");
    OIIO::ImageSpec config, spec;
    void *proxy_pointer = &reader;
    config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy_pointer);
    EXPECT_TRUE(in && in->open("t.exr", spec, config));
    std::vector<float> px(size_t(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    in->close();
    edit(spec, px);
    std::vector<unsigned char> out_bytes;
    OIIO::Filesystem::IOVecOutput writer(out_bytes);
    auto out = OIIO::ImageOutput::create("openexr");
    EXPECT_TRUE(out->set_ioproxy(&writer));
    EXPECT_TRUE(out->open("t.exr", spec));
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
    EXPECT_TRUE(out->close());
    return out_bytes;
}

void rehash(OIIO::ImageSpec &spec, const std::vector<float> &px) {
    OIIO::SHA1 sha(px.data(), px.size() * sizeof(float));
    spec.attribute("hairis:pixel_sha1", sha.digest());
}

void expect_refused(const std::vector<unsigned char> &bytes, const std::string &fragment) {
    const Expected<TableSet> t = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_FALSE(t.ok()) << "expected a refusal mentioning \"" << fragment << "\"";
    EXPECT_NE(t.error().message.find(fragment), std::string::npos) << t.error().message;
}

class TableFileRoundTrip : public ::testing::TestWithParam<int> {};
INSTANTIATE_TEST_SUITE_P(ThetaRCounts, TableFileRoundTrip, ::testing::Values(2, 3, 4, 19, 37));

TEST_P(TableFileRoundTrip, IsBitExact) {
    const TableSet t = small_tables(GetParam());
    const std::vector<unsigned char> bytes = encode(t);
    const Expected<TableSet> back = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_TRUE(back.ok()) << back.error().message;
    const TableSet &b = back.value();
    EXPECT_EQ(b.model, t.model);
    EXPECT_EQ(b.source, t.source);
    EXPECT_EQ(b.parameters, t.parameters);
    EXPECT_EQ(b.theta_r_nodes, t.theta_r_nodes);
    EXPECT_EQ(b.theta_i_count, t.theta_i_count);
    EXPECT_EQ(b.phi_count, t.phi_count);
    EXPECT_EQ(b.n_h_values, t.n_h_values);
    ASSERT_EQ(b.direct.size(), t.direct.size());
    ASSERT_EQ(b.multiple.size(), t.multiple.size());
    EXPECT_EQ(0, std::memcmp(b.direct.data(), t.direct.data(), t.direct.size() * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(b.multiple.data(), t.multiple.data(), t.multiple.size() * sizeof(float)));
}

TEST(TableFile, EncodingIsDeterministic) {
    EXPECT_EQ(encode(small_tables()), encode(small_tables()));
}

TEST(TableFile, FileRoundTripAndAtomicWrite) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "hairis_table_file_test";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "t.exr").string();
    ASSERT_FALSE(write_table_file(small_tables(), path));
    const Expected<TableSet> back = read_table_file(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back.value().direct, small_tables().direct);
    EXPECT_FALSE(std::filesystem::exists(path + ".tmp-hairis"));

    // An invalid table set is refused and leaves the previous file untouched.
    TableSet bad = small_tables();
    bad.direct[3] = -1.0f;
    const Status s = write_table_file(bad, path);
    ASSERT_TRUE(s);
    EXPECT_NE(s->message.find("negative"), std::string::npos) << s->message;
    EXPECT_TRUE(read_table_file(path).ok());

    // An unwritable destination is an error, not a crash.
    EXPECT_TRUE(write_table_file(small_tables(), (dir / "missing_dir" / "t.exr").string()));
    std::filesystem::remove_all(dir);
}

TEST(TableFile, MissingFileIsReported) {
    const Expected<TableSet> t = read_table_file("/nonexistent/hairis.exr");
    ASSERT_FALSE(t.ok());
    EXPECT_NE(t.error().message.find("cannot open"), std::string::npos);
}

TEST(TableFile, RefusesEmptyAndGarbage) {
    expect_refused({}, "empty");
    const std::vector<unsigned char> garbage(1000, 0x42);
    expect_refused(garbage, "not a readable OpenEXR file");
}

TEST(TableFile, RefusesTruncatedFile) {
    std::vector<unsigned char> bytes = encode(small_tables());
    for (size_t keep : {size_t(20), bytes.size() / 2, bytes.size() - 10}) {
        std::vector<unsigned char> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(keep));
        const Expected<TableSet> t = decode_table_exr(cut.data(), cut.size());
        EXPECT_FALSE(t.ok()) << "kept " << keep << " of " << bytes.size() << " bytes";
    }
}

TEST(TableFile, RefusesCorruptBytes) {
    std::vector<unsigned char> bytes = encode(small_tables());
    // Flip bytes in the compressed pixel data near the end.
    for (size_t n = bytes.size() - 40; n < bytes.size() - 20; ++n) bytes[n] ^= 0x5a;
    const Expected<TableSet> t = decode_table_exr(bytes.data(), bytes.size());
    EXPECT_FALSE(t.ok());
}

TEST(TableFile, RefusesWrongVersion) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.attribute("hairis:format_version", 3);
    });
    expect_refused(bytes, "format version 3 is not supported");
}

TEST(TableFile, RefusesVersionOneAskingForARebake) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.attribute("hairis:format_version", 1);
    });
    expect_refused(bytes, "re-bake the tables");
}

TEST(TableFile, RefusesForeignExr) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.erase_attribute("hairis:format_version");
    });
    expect_refused(bytes, "not a hairis table file");
}

TEST(TableFile, RefusesWrongSize) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.attribute("hairis:theta_i_count", 7);
    });
    expect_refused(bytes, "metadata needs");
}

TEST(TableFile, RefusesAbsurdSizeBeforeAllocating) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.attribute("hairis:phi_count", 1 << 30);
    });
    expect_refused(bytes, "phi_count must be an integer in [1, 4096]");
}

TEST(TableFile, RefusesNaN) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &px) {
        px[4 * 7] = std::numeric_limits<float>::quiet_NaN();
        rehash(spec, px);
    });
    expect_refused(bytes, "NaN");
}

TEST(TableFile, RefusesHashMismatch) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &, std::vector<float> &px) {
        px[4 * 11] *= 1.0001f;
    });
    expect_refused(bytes, "does not match its hash");
}

TEST(TableFile, RefusesWrongChannels) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.channelnames = {"X", "G", "B", "A"};
    });
    expect_refused(bytes, "channels R, G, B, A");
}

TEST(TableFile, RefusesInconsistentBand) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &px) {
        px[4 * 1 + 1] += 1.0f;  // column 1 lies inside the first n_h band
        rehash(spec, px);
    });
    expect_refused(bytes, "differs inside the n_h band");
}

// Overwrites the 4-byte little-endian size field of header attribute `name` (type `type`).
// Where attribute `name` of `type` keeps its 4-byte size field (its value follows); the
// test fails if the header has no such attribute.
size_t attribute_size_field(const std::vector<unsigned char> &bytes, const std::string &name,
                            const std::string &type) {
    const std::string key = name + std::string(1, '\0') + type + std::string(1, '\0');
    const auto at = std::search(bytes.begin(), bytes.end(), key.begin(), key.end());
    EXPECT_NE(at, bytes.end()) << name;
    return at == bytes.end() ? 0 : size_t(at - bytes.begin()) + key.size();
}

void set_attribute_size(std::vector<unsigned char> &bytes, const std::string &name, const std::string &type,
                        uint32_t size) {
    const size_t at = attribute_size_field(bytes, name, type);
    ASSERT_GT(at, 0u);
    for (size_t b = 0; b < 4; ++b) bytes[at + b] = (unsigned char)(size >> (8 * b));
}

TEST(TableFile, RefusesAttributeLargerThanTheData) {
    // OpenEXR itself would allocate the 2 GB the size field claims (found by fuzzing).
    std::vector<unsigned char> bytes = encode(small_tables());
    set_attribute_size(bytes, "hairis:model", "string", 0x7ffffff0u);
    expect_refused(bytes, "claims 2147483632 bytes; the data holds");
}

TEST(TableFile, RefusesFixedSizeAttributeWithAnotherSize) {
    // OpenEXR reads a compression attribute as 1 byte whatever its size field says, and then
    // the rest of the header out of step (found by fuzzing: it then allocated 1.7 GB).
    std::vector<unsigned char> bytes = encode(small_tables());
    set_attribute_size(bytes, "compression", "compression", 2);
    expect_refused(bytes, "of type compression has size 2");
}

TEST(TableFile, RefusesChannelListReadingPastItsSize) {
    // OpenEXR reads channel names up to their NUL, past the attribute's size if need be
    // (found by fuzzing: the rest of the header, read out of step, claimed 1.7 GB).
    std::vector<unsigned char> bytes = encode(small_tables());
    const size_t at = attribute_size_field(bytes, "channels", "chlist");
    ASSERT_GT(at, 0u);
    const auto last_channel = bytes.begin() + std::ptrdiff_t(at + 4 + 3 * 18);  // "R", "G", "B" before it
    std::fill(last_channel, last_channel + 18, (unsigned char)0xff);
    expect_refused(bytes, "OpenEXR attribute \"channels\": a channel entry");
}

TEST(TableFile, RefusesHugeDataWindowBeforeAllocating) {
    // A window of 4096 x 2^30 pixels in a small buffer: refused before OpenEXR allocates its
    // offset table or the reader its pixels.
    std::vector<unsigned char> bytes = encode(small_tables());
    const size_t at = attribute_size_field(bytes, "dataWindow", "box2i");
    ASSERT_GT(at, 0u);
    const int32_t window[4] = {0, 0, 4095, (1 << 30) - 1};
    std::memcpy(&bytes[at + 4], window, sizeof window);
    expect_refused(bytes, "a table has at most 4096 columns");
}

TEST(TableFile, RefusesMultiPartFiles) {
    std::vector<unsigned char> bytes = encode(small_tables());
    bytes[5] |= 0x10;  // the multi-part flag (bit 12 of the version field)
    expect_refused(bytes, "multi-part or deep");
}

// Where the chunk offset table starts: just past the header's terminating NUL.
size_t offset_table_start(const std::vector<unsigned char> &bytes) {
    size_t at = 8;  // magic number and version field
    while (bytes.at(at) != 0) {
        for (int strings = 0; strings < 2; ++strings)  // attribute name and type
            at = size_t(std::find(bytes.begin() + std::ptrdiff_t(at), bytes.end(), 0) - bytes.begin()) + 1;
        int32_t size = 0;
        std::memcpy(&size, &bytes.at(at), sizeof size);
        at += sizeof size + size_t(size);
    }
    return at + 1;
}

TEST(TableFile, RefusesChunkOffsetsBeforeTheData) {
    // A chunk offset of 2^64 - k: OpenEXR seeks there, and OIIO 2.4's in-memory reader then
    // copied from k bytes before the buffer (found by fuzzing; AddressSanitizer sees the read).
    // Now the read returns nothing, so OpenEXR meets the end of the file; before, it read
    // whatever lay before the buffer as a chunk header ("unexpected data block y coordinate").
    for (const uint64_t back : {1u, 4u, 8u, 4096u}) {
        std::vector<unsigned char> bytes = encode(small_tables());
        const uint64_t offset = ~uint64_t(0) - back + 1;
        std::memcpy(&bytes.at(offset_table_start(bytes)), &offset, sizeof offset);
        expect_refused(bytes, "Unexpected end of file");
    }
}

TEST(TableSetValidate, NamesTheProblem) {
    TableSet t = small_tables();
    t.theta_r_nodes[1] = t.theta_r_nodes[0];
    ASSERT_TRUE(t.validate());
    EXPECT_NE(t.validate()->message.find("strictly increasing"), std::string::npos);
    t = small_tables();
    t.model = "lambert";
    EXPECT_NE(t.validate()->message.find("model must be"), std::string::npos);
    t = small_tables();
    t.multiple.pop_back();
    EXPECT_NE(t.validate()->message.find("multiple table holds"), std::string::npos);
    EXPECT_FALSE(small_tables().validate());
}

TEST(TableFile, CanonicalParameters) {
    EXPECT_EQ(canonical_parameters({{"ior", 1.55}, {"coat", 0.0}}), "ior=1.55;coat=0");
}

}  // namespace
}  // namespace hairis
