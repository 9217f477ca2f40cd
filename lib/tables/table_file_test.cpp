// Table files (format v2, table_file.h): both parts round-trip bit for bit and lie in the
// image where the format says, and a damaged or inconsistent file is refused with a message
// naming the problem, before anything is allocated for what its header claims.
#include "tables/table_file.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/hash.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "exr_image.h"
#include "same_bits.h"

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

using testing::same_bits;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A far part only (as a Marschner bake or a v1 file holds): θ_r nodes × 6 θ_i × 10 φ, n_h 1, 2, 4.
TableSet far_tables(int theta_r_count = 3) {
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

// A near part whose stored values are all distinct (a value read from another pixel cannot
// round-trip), with a zero mass per row, a subnormal edge value and cone flags on some rows.
std::shared_ptr<const NearFieldData> near_part(int nodes, int cells) {
    auto n = std::make_shared<NearFieldData>();
    n->theta_o_nodes = nodes;
    n->theta_i_cells = cells;
    for (int row = 0; row < n->rows(); ++row) {
        for (int k = 0; k < cells; ++k)
            n->mass.push_back(k == row % cells ? 0.0f : 1e-3f * float(1 + row * cells + k) + 1e-9f * float(k));
        for (int k = 0; k <= cells; ++k)
            n->edge.push_back(row == 1 && k == 0 ? 1e-40f : 0.75f + 0.01f * float(row * (cells + 1) + k));
        n->integral.push_back(0.25f + float(row) / 7.0f);
        n->cone.push_back(row % 3 == 1);
    }
    return n;
}

// A v2 Chiang table set: the far part of far_tables() and a near part of `nodes` θ_o nodes and
// `cells` θ_i cells. The default near part (13 columns) is wider than the far part (10), so
// the far rows carry padding.
TableSet small_tables(int theta_r_count = 3, int nodes = 2, int cells = 12) {
    TableSet t = far_tables(theta_r_count);
    t.near_field = near_part(nodes, cells);
    return t;
}

// The image rows of small_tables()'s far part (3 θ_r × 6 θ_i), where its near part starts.
constexpr int kFarRows = 18;

using namespace testing;  // the table-file image helpers (exr_image.h)

// Re-encodes valid table bytes after letting `edit` change the header or the pixels, the way
// a foreign or damaged writer would.
std::vector<unsigned char> tamper(const std::vector<unsigned char> &valid,
                                  const std::function<void(OIIO::ImageSpec &, std::vector<float> &)> &edit) {
    Image image = read_image(valid);
    edit(image.spec, image.px);
    return write_image(image);
}

// Bytes of valid tables `t` with one channel of one pixel set to `value`, the hash made to
// match (so the check that refuses it is the one about that pixel).
std::vector<unsigned char> with_pixel(const TableSet &t, int x, int y, int c, float value, bool fix_hash = true) {
    Image image = read_image(encode(t));
    image.at(x, y, c) = value;
    if (fix_hash) rehash(image);
    return write_image(image);
}

// The same with channel c set to `value` along a whole near-part row (columns 0..cells).
std::vector<unsigned char> with_row(const TableSet &t, int y, int c, float value) {
    Image image = read_image(encode(t));
    for (int k = 0; k <= t.near_field->theta_i_cells; ++k) image.at(k, y, c) = value;
    rehash(image);
    return write_image(image);
}

std::vector<unsigned char> with_attribute(const TableSet &t, const std::string &name, const std::string &value) {
    return tamper(encode(t), [&](OIIO::ImageSpec &spec, std::vector<float> &) { spec.attribute(name, value); });
}

void expect_same_far_part(const TableSet &b, const TableSet &t) {
    EXPECT_EQ(b.model, t.model);
    EXPECT_EQ(b.source, t.source);
    EXPECT_EQ(b.parameters, t.parameters);
    EXPECT_EQ(b.theta_r_nodes, t.theta_r_nodes);
    EXPECT_EQ(b.theta_i_count, t.theta_i_count);
    EXPECT_EQ(b.phi_count, t.phi_count);
    EXPECT_EQ(b.n_h_values, t.n_h_values);
    ASSERT_EQ(b.direct.size(), t.direct.size());
    ASSERT_EQ(b.multiple.size(), t.multiple.size());
    EXPECT_TRUE(same_bits(b.direct, t.direct));
    EXPECT_TRUE(same_bits(b.multiple, t.multiple));
}

void expect_same_near_part(const NearFieldData &b, const NearFieldData &t) {
    EXPECT_EQ(b.theta_o_nodes, t.theta_o_nodes);
    EXPECT_EQ(b.theta_i_cells, t.theta_i_cells);
    ASSERT_EQ(b.mass.size(), t.mass.size());
    ASSERT_EQ(b.edge.size(), t.edge.size());
    ASSERT_EQ(b.integral.size(), t.integral.size());
    EXPECT_TRUE(same_bits(b.mass, t.mass));
    EXPECT_TRUE(same_bits(b.edge, t.edge));
    EXPECT_TRUE(same_bits(b.integral, t.integral));
    EXPECT_EQ(b.cone, t.cone);
}

class TableFileRoundTrip : public ::testing::TestWithParam<int> {};
INSTANTIATE_TEST_SUITE_P(ThetaRCounts, TableFileRoundTrip, ::testing::Values(2, 3, 4, 19, 37));

TEST_P(TableFileRoundTrip, IsBitExact) {
    const TableSet t = far_tables(GetParam());
    const std::vector<unsigned char> bytes = encode(t);
    const Expected<TableSet> back = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_TRUE(back.ok()) << back.error().message;
    expect_same_far_part(back.value(), t);
    EXPECT_FALSE(back.value().near_field);
    EXPECT_EQ(read_image(bytes).spec.get_string_attribute("hairis:parts"), "far");
}

struct NearShape {
    int theta_r_count, nodes, cells;
};
// The near part wider than the far part (10 columns; the far rows are padded), narrower (the
// near rows are), as wide, and larger on both axes.
class TableFileNearRoundTrip : public ::testing::TestWithParam<NearShape> {};
INSTANTIATE_TEST_SUITE_P(Shapes, TableFileNearRoundTrip,
                         ::testing::Values(NearShape{3, 2, 12}, NearShape{3, 2, 4}, NearShape{3, 2, 9},
                                           NearShape{19, 7, 40}, NearShape{2, 121, 90}),
                         [](const ::testing::TestParamInfo<NearShape> &shape) {
                             return "theta_r" + std::to_string(shape.param.theta_r_count) + "_nodes" +
                                    std::to_string(shape.param.nodes) + "_cells" + std::to_string(shape.param.cells);
                         });

TEST_P(TableFileNearRoundTrip, IsBitExact) {
    const NearShape shape = GetParam();
    const TableSet t = small_tables(shape.theta_r_count, shape.nodes, shape.cells);
    const std::vector<unsigned char> bytes = encode(t);
    const Expected<TableSet> back = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_TRUE(back.ok()) << back.error().message;
    expect_same_far_part(back.value(), t);
    ASSERT_TRUE(back.value().near_field);
    expect_same_near_part(*back.value().near_field, *t.near_field);
}

TEST_P(TableFileNearRoundTrip, TheImageHoldsThePartsWhereTheFormatSays) {
    // Read with OpenImageIO alone, pixel by pixel against table_file.h's layout.
    const NearShape shape = GetParam();
    const TableSet t = small_tables(shape.theta_r_count, shape.nodes, shape.cells);
    Image image = read_image(encode(t));
    const int far_rows = shape.theta_r_count * t.theta_i_count, cells = shape.cells;
    const int width = std::max(t.phi_count, cells + 1);
    ASSERT_EQ(image.spec.width, width);
    ASSERT_EQ(image.spec.height, far_rows + 4 * shape.nodes);
    ASSERT_EQ(image.spec.nchannels, 4);
    EXPECT_EQ(image.spec.get_int_attribute("hairis:format_version"), 2);
    EXPECT_EQ(image.spec.get_string_attribute("hairis:parts"), "far,near");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:near"),
              "row=" + std::to_string(far_rows) + ";theta_o=" + std::to_string(shape.nodes) +
                  ";theta_i=" + std::to_string(cells));
    for (int y = 0; y < far_rows; ++y)
        for (int x = 0; x < width; ++x) {
            const int r = y / t.theta_i_count, i = y % t.theta_i_count;
            const bool inside = x < t.phi_count;
            const int band = x * 3 / t.phi_count;  // 3 equal bands of columns, one per n_h
            EXPECT_EQ(image.at(x, y, 0), inside ? t.direct[size_t(y) * 10 + size_t(x)] : 0.0f) << x << "," << y;
            EXPECT_EQ(image.at(x, y, 1), inside ? t.multiple[(size_t(r) * 3 + size_t(band)) * 6 + size_t(i)] : 0.0f)
                << x << "," << y;
            EXPECT_EQ(image.at(x, y, 2), 0.0f) << x << "," << y;
            EXPECT_EQ(image.at(x, y, 3), inside ? 1.0f : 0.0f) << x << "," << y;
        }
    const NearFieldData &n = *t.near_field;
    for (int q = 0; q < n.rows(); ++q)
        for (int k = 0; k < width; ++k) {
            const int y = far_rows + q;
            const bool inside = k <= cells;
            EXPECT_EQ(image.at(k, y, 0), k < cells ? n.mass[size_t(q) * size_t(cells) + size_t(k)] : 0.0f) << k << "," << y;
            EXPECT_EQ(image.at(k, y, 1), inside ? n.edge[size_t(q) * size_t(cells + 1) + size_t(k)] : 0.0f) << k << "," << y;
            EXPECT_EQ(image.at(k, y, 2), inside ? n.integral[size_t(q)] : 0.0f) << k << "," << y;
            EXPECT_EQ(image.at(k, y, 3), inside ? float(n.cone[size_t(q)]) : 0.0f) << k << "," << y;
        }
}

TEST(TableFile, EncodingIsDeterministic) {
    EXPECT_EQ(encode(small_tables()), encode(small_tables()));
    EXPECT_EQ(encode(far_tables()), encode(far_tables()));
}

TEST(TableFile, FileRoundTripAndAtomicWrite) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "hairis_table_file_test";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "t.exr").string();
    ASSERT_FALSE(write_table_file(small_tables(), path));
    const Expected<TableSet> back = read_table_file(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back.value().direct, small_tables().direct);
    ASSERT_TRUE(back.value().near_field);
    EXPECT_EQ(back.value().near_field->mass, small_tables().near_field->mass);
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
    for (const TableSet &t : {small_tables(), far_tables()}) {
        std::vector<unsigned char> bytes = encode(t);
        for (size_t keep : {size_t(20), bytes.size() / 2, bytes.size() - 10, bytes.size() - 1}) {
            std::vector<unsigned char> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(keep));
            const Expected<TableSet> back = decode_table_exr(cut.data(), cut.size());
            EXPECT_FALSE(back.ok()) << "kept " << keep << " of " << bytes.size() << " bytes";
        }
    }
}

TEST(TableFile, RefusesCorruptBytes) {
    std::vector<unsigned char> bytes = encode(small_tables());
    // Flip bytes in the compressed pixel data near the end (the near part's last chunk).
    for (size_t n = bytes.size() - 40; n < bytes.size() - 20; ++n) bytes[n] ^= 0x5a;
    const Expected<TableSet> t = decode_table_exr(bytes.data(), bytes.size());
    EXPECT_FALSE(t.ok());
}

TEST(TableFile, RefusesWrongVersion) {
    for (const int version : {0, 3, 1 << 30}) {
        const auto bytes = tamper(encode(small_tables()), [&](OIIO::ImageSpec &spec, std::vector<float> &) {
            spec.attribute("hairis:format_version", version);
        });
        expect_refused(bytes, "format version " + std::to_string(version) + " is not supported (this build reads version 2)");
    }
}

TEST(TableFile, RefusesVersionOneAskingForARebake) {
    // A file as version 1 wrote it: the far part alone, no hairis:parts or hairis:near.
    const auto v1 = tamper(encode(far_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.attribute("hairis:format_version", 1);
        spec.erase_attribute("hairis:parts");
    });
    expect_refused(v1, "format version 1 (baked by hairis 0.1) lacks what this build samples");
    expect_refused(v1, "re-bake the tables");
    // Also with the version alone changed.
    const auto relabelled = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.attribute("hairis:format_version", 1);
    });
    expect_refused(relabelled, "re-bake the tables");
}

TEST(TableFile, RefusesForeignExr) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.erase_attribute("hairis:format_version");
    });
    expect_refused(bytes, "not a hairis table file");
}

TEST(TableFile, RefusesWrongSize) {
    // The far part's counts against the image: a far-only file, and one with a near part.
    expect_refused(tamper(encode(far_tables()),
                          [](OIIO::ImageSpec &spec, std::vector<float> &) { spec.attribute("hairis:theta_i_count", 7); }),
                   "image is 10x18 but the metadata needs 10x21");
    expect_refused(tamper(encode(small_tables()),
                          [](OIIO::ImageSpec &spec, std::vector<float> &) { spec.attribute("hairis:phi_count", 14); }),
                   "image is 13x26 but the metadata needs 14x26");
    // More far rows move where the near part must start.
    expect_refused(tamper(encode(small_tables()),
                          [](OIIO::ImageSpec &spec, std::vector<float> &) { spec.attribute("hairis:theta_i_count", 7); }),
                   "start at row 21, after the far part");
}

TEST(TableFile, RefusesAbsurdSizeBeforeAllocating) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.attribute("hairis:phi_count", 1 << 30);
    });
    expect_refused(bytes, "phi_count must be an integer in [1, 4096]");
}

TEST(TableFile, RefusesNaN) {
    Image image = read_image(encode(small_tables()));
    image.px[4 * 7] = kNaN;
    rehash(image);
    expect_refused(write_image(image), "pixel (7, 0) holds NaN or infinity");
}

TEST(TableFile, RefusesHashMismatch) {
    Image image = read_image(encode(small_tables()));
    ASSERT_GT(image.at(1, 1, 0), 0.0f);
    image.at(1, 1, 0) *= 1.0001f;
    expect_refused(write_image(image), "does not match its hash");
}

TEST(TableFile, TheHashCoversTheWholeImage) {
    // A change anywhere, the parts' padding included, is refused as a hash mismatch first.
    struct Place {
        TableSet tables;
        int x, y, c;
        float value;
    };
    const Place places[] = {
        {small_tables(), 3, 2, 0, 0.5f},                        // far part
        {small_tables(), 11, 5, 2, 1.0f},                       // the far rows' padding
        {small_tables(), 4, kFarRows + 6, 1, 0.125f},           // near part: an edge value
        {small_tables(), 12, kFarRows + 7, 3, 0.0f},            // near part: the last pixel
        {small_tables(3, 2, 4), 7, kFarRows + 1, 0, 1e-30f},    // the near rows' padding
        {small_tables(3, 2, 4), 9, kFarRows + 7, 3, -0.0f},     // the last pixel (sign bit)
    };
    for (const Place &p : places) {
        const float before = read_image(encode(p.tables)).at(p.x, p.y, p.c);
        ASSERT_NE(std::memcmp(&before, &p.value, sizeof before), 0);  // a change, bit for bit
        SCOPED_TRACE(std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.c));
        expect_refused(with_pixel(p.tables, p.x, p.y, p.c, p.value, false), "does not match its hash");
    }
}

TEST(TableFile, RefusesWrongChannels) {
    const auto bytes = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.channelnames = {"X", "G", "B", "A"};
    });
    expect_refused(bytes, "channels R, G, B, A");
}

TEST(TableFile, RefusesInconsistentBand) {
    Image image = read_image(encode(small_tables()));
    image.px[4 * 1 + 1] += 1.0f;  // column 1 lies inside the first n_h band
    rehash(image);
    expect_refused(write_image(image), "differs inside the n_h band");
}

// ---- The near part --------------------------------------------------------------------------

TEST(TableFileNearPart, RefusesNonZeroPixelsInTheFarRowsPadding) {
    // small_tables(): far columns 0..9, image 13 wide; every channel, on both sides of the part.
    for (int c = 0; c < 4; ++c)
        for (const auto &[x, y] : {std::pair{10, 0}, std::pair{12, 17}, std::pair{11, 9}})
            expect_refused(with_pixel(small_tables(), x, y, c, 1e-3f),
                           "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") lies outside every part and must be 0");
}

TEST(TableFileNearPart, RefusesNonZeroPixelsInTheNearRowsPadding) {
    // A near part of 4 cells: columns 0..4 of image rows 18..25, image 10 wide.
    const TableSet t = small_tables(3, 2, 4);
    for (int c = 0; c < 4; ++c)
        for (const auto &[x, y] : {std::pair{5, kFarRows}, std::pair{9, kFarRows + 7}, std::pair{6, kFarRows + 3}})
            expect_refused(with_pixel(t, x, y, c, -2.0f),
                           "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") lies outside every part and must be 0");
}

TEST(TableFileNearPart, RefusesBOrAThatChangesAlongARow) {
    const TableSet t = small_tables();
    const float integral = t.near_field->integral[2];
    // B (the lobe integral) in the middle of row 2 and in its last column (the upper edge).
    expect_refused(with_pixel(t, 5, kFarRows + 2, 2, integral * 1.5f),
                   "B and A must be constant along a near-field row at pixel (5, 20)");
    expect_refused(with_pixel(t, 12, kFarRows + 2, 2, integral + 1.0f),
                   "B and A must be constant along a near-field row at pixel (12, 20)");
    // A (the cone flag): row 1 draws from the cone (1), row 2 does not (0).
    ASSERT_TRUE(t.near_field->cone[1] && !t.near_field->cone[2]);
    expect_refused(with_pixel(t, 3, kFarRows + 1, 3, 0.0f),
                   "B and A must be constant along a near-field row at pixel (3, 19)");
    expect_refused(with_pixel(t, 12, kFarRows + 2, 3, 1.0f),
                   "B and A must be constant along a near-field row at pixel (12, 20)");
}

TEST(TableFileNearPart, RefusesAConeFlagOtherThanZeroOrOne) {
    for (const float flag : {0.5f, 2.0f, -1.0f, 1.0f + 1e-7f})
        expect_refused(with_row(small_tables(), kFarRows + 4, 3, flag),
                       "A (the cone flag) must be 0 or 1 at pixel (0, 22)");
}

TEST(TableFileNearPart, RefusesRInTheLastColumn) {
    // The last column holds the upper edge of the last cell: it has no mass.
    expect_refused(with_pixel(small_tables(), 12, kFarRows + 5, 0, 1e-6f),
                   "R must be 0 in the near part's last column at pixel (12, 23)");
    expect_refused(with_pixel(small_tables(3, 2, 4), 4, kFarRows, 0, 3.0f),
                   "R must be 0 in the near part's last column at pixel (4, 18)");
}

TEST(TableFileNearPart, RefusesAMissingNearAttribute) {
    const auto erased = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.erase_attribute("hairis:near");
    });
    expect_refused(erased, "hairis:parts is \"far,near\" but there is no hairis:near attribute");
    // Of another type.
    const auto number = tamper(encode(small_tables()), [](OIIO::ImageSpec &spec, std::vector<float> &) {
        spec.erase_attribute("hairis:near");
        spec.attribute("hairis:near", 18);
    });
    expect_refused(number, "hairis:near");
}

TEST(TableFileNearPart, RefusesAGarbledNearAttribute) {
    const std::pair<const char *, const char *> cases[] = {
        {"row=18;theta_o=2;theta_i", "hairis:near"},
        {"row=18;theta_o=two;theta_i=12", "hairis:near: theta_o must be an integer in [2, 1024] (got \"two\")"},
        {"row=18;theta_o=2;theta_i=12;theta_r=3", "hairis:near: unknown option \"theta_r\""},
        {"row=18;theta_o=2", "hairis:near must give theta_o and theta_i"},
        {"theta_o=2;theta_i=12", "start at row 18"},
        {"", "hairis:near"},  // OpenImageIO may drop an empty string attribute
        {"row=18;row=18;theta_o=2;theta_i=12", "hairis:near"},
    };
    for (const auto &[text, fragment] : cases) {
        SCOPED_TRACE(text);
        expect_refused(with_attribute(small_tables(), "hairis:near", text), fragment);
    }
}

TEST(TableFileNearPart, RefusesAWrongRowOrCounts) {
    expect_refused(with_attribute(small_tables(), "hairis:near", "row=17;theta_o=2;theta_i=12"),
                   "hairis:near must give theta_o and theta_i and start at row 18, after the far part");
    expect_refused(with_attribute(small_tables(), "hairis:near", "row=19;theta_o=2;theta_i=12"), "start at row 18");
    // Counts the image does not hold: a row or a column of cells more or less.
    expect_refused(with_attribute(small_tables(), "hairis:near", "row=18;theta_o=3;theta_i=12"),
                   "image is 13x26 but the metadata needs 13x30");
    expect_refused(with_attribute(small_tables(), "hairis:near", "row=18;theta_o=2;theta_i=13"),
                   "image is 13x26 but the metadata needs 14x26");
    expect_refused(with_attribute(small_tables(), "hairis:near", "row=18;theta_o=2;theta_i=11"),
                   "image is 13x26 but the metadata needs 12x26");
    // Where the near part is narrower than the far part, one cell more keeps the image's width:
    // column 5 (padding) is then read as the last column, whose B must be the row's integral.
    expect_refused(with_attribute(small_tables(3, 2, 4), "hairis:near", "row=18;theta_o=2;theta_i=5"),
                   "B and A must be constant along a near-field row at pixel (5, 18)");
}

TEST(TableFileNearPart, RefusesAbsurdCountsBeforeAllocating) {
    // Out of range: refused as the attribute is read. In range but larger than the image:
    // refused by the size check, before any pixel is read.
    const std::pair<const char *, const char *> cases[] = {
        {"row=18;theta_o=2147483647;theta_i=12", "theta_o must be an integer in [2, 1024]"},
        {"row=18;theta_o=2;theta_i=1073741824", "theta_i must be an integer in [4, 4096]"},
        {"row=18;theta_o=-4;theta_i=12", "theta_o must be an integer in [2, 1024]"},
        {"row=18;theta_o=1;theta_i=12", "theta_o must be an integer in [2, 1024]"},
        {"row=18;theta_o=2;theta_i=3", "theta_i must be an integer in [4, 4096]"},
        {"row=9223372036854775807;theta_o=2;theta_i=12", "row must be an integer in [0, 67108864]"},
        {"row=18;theta_o=1024;theta_i=4096", "image is 13x26 but the metadata needs 4097x4114"},
    };
    for (const auto &[text, fragment] : cases) {
        SCOPED_TRACE(text);
        expect_refused(with_attribute(small_tables(), "hairis:near", text), fragment);
    }
}

TEST(TableFileNearPart, RefusesUnknownParts) {
    for (const char *parts : {"", "near", "near,far", "far,near,far", "far,mid", "far, near", "FAR,NEAR", "far,huang"}) {
        SCOPED_TRACE(parts);
        expect_refused(with_attribute(small_tables(), "hairis:parts", parts),
                       "hairis:parts must be \"far\", \"far,near\", \"huang\", \"huang,f\", \"huang,f,absorption\", "
                       "\"huang,multiple\", \"huang,f,multiple\" or \"huang,f,absorption,multiple\"");
    }
    // A Huang part claimed on a Chiang file.
    expect_refused(with_attribute(small_tables(), "hairis:parts", "huang"), "is for model huang2022");
    // "far" alone leaves the near rows unaccounted for.
    expect_refused(with_attribute(small_tables(), "hairis:parts", "far"), "image is 13x26 but the metadata needs 10x18");
    // A near part claimed on a file that has none.
    expect_refused(with_attribute(far_tables(), "hairis:parts", "far,near"), "no hairis:near attribute");
}

TEST(TableFileNearPart, RefusesANearPartOnAnotherModel) {
    expect_refused(with_attribute(small_tables(), "hairis:model", "marschner2003"),
                   "a near-field part is only for chiang2016 tables (got marschner2003)");
    // Also in memory: such a set is never written.
    TableSet t = small_tables();
    t.model = "marschner2003";
    EXPECT_FALSE(encode_table_exr(t).ok());
}

TEST(TableFileNearPart, RefusesNaNOrInfinity) {
    const TableSet t = small_tables();
    expect_refused(with_pixel(t, 2, kFarRows + 3, 0, kNaN), "pixel (2, 21) holds NaN or infinity");     // mass
    expect_refused(with_pixel(t, 12, kFarRows + 7, 1, kInf), "pixel (12, 25) holds NaN or infinity");   // edge
    expect_refused(with_row(t, kFarRows + 6, 2, -kInf), "pixel (0, 24) holds NaN or infinity");        // integral
    expect_refused(with_row(t, kFarRows, 3, kNaN), "pixel (0, 18) holds NaN or infinity");             // cone flag
}

TEST(TableFileNearPart, RefusesNegativeValues) {
    const TableSet t = small_tables();
    // Row q's cell k is mass q·12 + k, its edge k is edge q·13 + k.
    expect_refused(with_pixel(t, 2, kFarRows + 3, 0, -1e-3f), "near-field table: mass 38 must be finite and >= 0");
    expect_refused(with_pixel(t, 12, kFarRows + 1, 1, -0.5f), "near-field table: edge value 25 must be finite and >= 0");
    expect_refused(with_row(t, kFarRows + 6, 2, -0.25f), "near-field table: integral 6 must be finite and >= 0");
    // The smallest negative number too.
    expect_refused(with_pixel(t, 0, kFarRows, 1, -std::numeric_limits<float>::denorm_min()), "edge value 0 must be finite");
}

TEST(TableFileNearPart, AcceptsEveryValidValue) {
    // Zero rows (a lobe with no mass), zero and huge values, subnormals and both cone flags
    // are valid and read back as written.
    TableSet t = small_tables();
    auto n = std::make_shared<NearFieldData>(*t.near_field);
    std::fill(n->mass.begin(), n->mass.begin() + 12, 0.0f);
    std::fill(n->edge.begin(), n->edge.begin() + 13, 0.0f);
    n->integral[0] = 0.0f;
    n->mass[13] = std::numeric_limits<float>::max();
    n->edge[14] = std::numeric_limits<float>::denorm_min();
    n->integral[7] = std::numeric_limits<float>::max();
    n->cone = {1, 1, 1, 1, 0, 0, 0, 0};
    t.near_field = n;
    const std::vector<unsigned char> bytes = encode(t);
    const Expected<TableSet> back = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_TRUE(back.ok()) << back.error().message;
    expect_same_near_part(*back.value().near_field, *n);
}

TEST(TableFileNearPart, RefusesToEncodeAnInvalidNearPart) {
    TableSet t = small_tables();
    auto n = std::make_shared<NearFieldData>(*t.near_field);
    n->edge.pop_back();
    t.near_field = n;
    const Expected<std::vector<unsigned char>> bytes = encode_table_exr(t);
    ASSERT_FALSE(bytes.ok());
    EXPECT_NE(bytes.error().message.find("near-field table: holds 96 masses, 103 edges"), std::string::npos)
        << bytes.error().message;
}

// ---- The EXR header, before OpenEXR reads it --------------------------------------------

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
    for (const char *name : {"hairis:model", "hairis:near", "hairis:parts"}) {
        std::vector<unsigned char> bytes = encode(small_tables());
        set_attribute_size(bytes, name, "string", 0x7ffffff0u);
        expect_refused(bytes, "OpenEXR attribute \"" + std::string(name) + "\" claims 2147483632 bytes; the data holds");
    }
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
    expect_refused(bytes, "a table has at most 4097 columns and 67108864 pixels");
}

TEST(TableFile, TheWidestNearPartRoundTrips) {
    // 4096 θ_i cells take 4097 columns (the last one holds the upper edge), one more than a
    // far part may have.
    const TableSet t = small_tables(3, 2, kMaxTableAxisCells);
    const std::vector<unsigned char> bytes = encode(t);
    const Expected<TableSet> back = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_TRUE(back.ok()) << back.error().message;
    expect_same_near_part(*back.value().near_field, *t.near_field);
    // One column more is refused before OpenEXR reads the header.
    std::vector<unsigned char> wider = bytes;
    const size_t at = attribute_size_field(wider, "dataWindow", "box2i");
    ASSERT_GT(at, 0u);
    const int32_t window[4] = {0, 0, kMaxTableAxisCells + 1, 25};
    std::memcpy(&wider[at + 4], window, sizeof window);
    expect_refused(wider, "the image is 4098x26 pixels; a table has at most 4097 columns");
}

TEST(TableFile, RefusesToEncodeAnImageLargerThanAFileHolds) {
    // A far part of 4M narrow rows is valid, and so is a near part 4097 columns wide; the
    // image stacking them, 4097 x 4M pixels, is refused before it is allocated.
    TableSet t;
    t.model = "chiang2016";
    t.source = "exact";
    t.theta_r_nodes.resize(kMaxThetaRNodes);
    for (int r = 0; r < kMaxThetaRNodes; ++r) t.theta_r_nodes[size_t(r)] = float(-kHalfPi + kPi * (r + 0.5) / kMaxThetaRNodes);
    t.theta_i_count = kMaxTableAxisCells;
    t.phi_count = 1;
    t.direct.assign(size_t(kMaxThetaRNodes) * kMaxTableAxisCells, 1.0f);
    t.near_field = near_part(2, kMaxTableAxisCells);
    ASSERT_FALSE(t.validate()) << t.validate()->message;
    const Expected<std::vector<unsigned char>> bytes = encode_table_exr(t);
    ASSERT_FALSE(bytes.ok());
    EXPECT_NE(bytes.error().message.find("the image would be 4097x4194312 pixels; a table file holds at most"),
              std::string::npos)
        << bytes.error().message;
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
    t = small_tables();
    t.model = "marschner2003";
    EXPECT_NE(t.validate()->message.find("a near-field part is only for chiang2016 tables"), std::string::npos);
    t = small_tables();
    auto n = std::make_shared<NearFieldData>(*t.near_field);
    n->cone[3] = 2;
    t.near_field = n;
    EXPECT_NE(t.validate()->message.find("near-field table: cone flag 3 must be 0 or 1"), std::string::npos);
    n->cone[3] = 0;
    n->theta_o_nodes = 1;
    EXPECT_NE(t.validate()->message.find("theta_o nodes"), std::string::npos);
    EXPECT_FALSE(small_tables().validate());
    EXPECT_FALSE(far_tables().validate());
}

TEST(TableFile, CanonicalParameters) {
    EXPECT_EQ(canonical_parameters({{"ior", 1.55}, {"coat", 0.0}}), "ior=1.55;coat=0");
}

}  // namespace
}  // namespace hairis
