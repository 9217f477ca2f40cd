// Table files of huang2022 fibers (table_file.h, the "huang" part): the Huang table round-trips
// bit for bit and lies in the image where the format says, the TABLE strategy sampled from a
// loaded file is exact, and damaged or inconsistent files are refused naming the problem.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/hash.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "exr_image.h"
#include "same_bits.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>

#include "chi2.h"
#include "huang_table_breaks.h"
#include "core/frame.h"
#include "fiber/principled_hair.h"
#include "sampling/huang_table_sampler.h"
#include "sampling/strategy.h"
#include "tables/bake.h"
#include "tables/huang_bake.h"
#include "tables/table_file.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;
using testing::same_bits;

std::shared_ptr<const HuangFiber> huang_fiber(float aspect_ratio = 0.85f) {
    HuangParams p;  // Blender's default node: its default colour mapped with Huang's roughness
    p.sigma_a = principled_hair::sigma_from_reflectance({0.017513f, 0.005763f, 0.002059f}, p.roughness);
    p.aspect_ratio = aspect_ratio;
    return std::make_shared<const HuangFiber>(HuangFiber::create(p).value());
}

BakeOptions small_bake() {
    BakeOptions o;
    o.huang = {8, 3, 16, 24};
    o.huang_multiple = false;  // the multiple part's files are tested with distinct values
    return o;
}

// A baked table set of the default fiber at small_bake()'s resolution (baked once).
const TableSet &baked() {
    static const TableSet t = [] {
        const auto fiber = huang_fiber();
        return bake_tables(*fiber, huang_parameters(fiber->params()), small_bake()).value();
    }();
    return t;
}

// A Huang set whose values are all distinct (a value read from another pixel cannot
// round-trip), with a zero and a subnormal value.
TableSet distinct_tables(int theta_o = 3, int phi_o = 2, int theta_i = 4, int phi = 5) {
    auto h = std::make_shared<HuangTableSet>();
    h->parameters = huang_parameters(HuangParams{});
    for (int r = 0; r < theta_o; ++r) h->theta_o_nodes.push_back(float(-1.2 + 2.4 * r / std::max(theta_o - 1, 1)));
    h->phi_o_nodes = huang_phi_o_nodes(phi_o);
    h->theta_i_count = theta_i;
    h->phi_count = phi;
    const int cells = phi_o * theta_o * theta_i * phi;
    for (int n = 0; n < cells; ++n) h->values.push_back(n == 1 ? 0.0f : n == 2 ? 1e-40f : 0.5f + 0.001f * float(n));
    TableSet t;
    t.model = "huang2022";
    t.source = "exact";
    t.parameters = h->parameters;
    t.huang = std::move(h);
    return t;
}

// distinct_tables() with a multiple part of distinct values: 3 θ_r nodes, 4 θ_i cells, n_h 1, 4.
TableSet distinct_with_multiple(int theta_o = 3, int phi_o = 2, int theta_i = 4, int phi = 5) {
    TableSet t = distinct_tables(theta_o, phi_o, theta_i, phi);
    t.theta_r_nodes = {-1.0f, 0.25f, 1.1f};
    t.theta_i_count = 4;
    t.n_h_values = {1, 4};
    for (int n = 0; n < 3 * 2 * 4; ++n) t.multiple.push_back(n == 3 ? 0.0f : 2.0f + 0.01f * float(n));
    return t;
}

using namespace testing;  // the table-file image helpers (exr_image.h)

// Valid bytes of `t` re-encoded after `edit` changed the header or the pixels; the hash is
// made to match the edited pixels unless `fix_hash` is false.
std::vector<unsigned char> tamper(const TableSet &t, const std::function<void(Image &)> &edit, bool fix_hash = true) {
    Image image = read_image(encode(t));
    edit(image);
    if (fix_hash) rehash(image);
    return write_image(image);
}

void expect_same_huang_part(const TableSet &b, const TableSet &t) {
    EXPECT_EQ(b.model, t.model);
    EXPECT_EQ(b.source, t.source);
    // Parameters are recorded to 9 significant digits (canonical_parameters), values bit for bit.
    EXPECT_EQ(canonical_parameters(b.parameters), canonical_parameters(t.parameters));
    ASSERT_TRUE(b.huang && t.huang);
    EXPECT_FALSE(b.has_far_field());
    EXPECT_FALSE(b.near_field);
    EXPECT_EQ(canonical_parameters(b.huang->parameters), canonical_parameters(t.huang->parameters));
    EXPECT_EQ(b.huang->theta_o_nodes, t.huang->theta_o_nodes);
    EXPECT_EQ(b.huang->phi_o_nodes, t.huang->phi_o_nodes);
    EXPECT_EQ(b.huang->theta_i_count, t.huang->theta_i_count);
    EXPECT_EQ(b.huang->phi_count, t.huang->phi_count);
    ASSERT_EQ(b.huang->values.size(), t.huang->values.size());
    EXPECT_TRUE(same_bits(b.huang->values, t.huang->values));
    EXPECT_EQ(b.has_multiple(), t.has_multiple());
    EXPECT_EQ(b.theta_r_nodes, t.theta_r_nodes);
    EXPECT_EQ(b.theta_i_count, t.theta_i_count);
    EXPECT_EQ(b.n_h_values, t.n_h_values);
    ASSERT_EQ(b.multiple.size(), t.multiple.size());
    EXPECT_TRUE(same_bits(b.multiple, t.multiple));
    ASSERT_EQ(b.huang->f.size(), t.huang->f.size());
    EXPECT_TRUE(same_bits(b.huang->f, t.huang->f));
    ASSERT_EQ(b.huang->absorption_nodes.size(), t.huang->absorption_nodes.size());
    EXPECT_TRUE(same_bits(b.huang->absorption_nodes, t.huang->absorption_nodes));
    ASSERT_EQ(b.huang->absorption.size(), t.huang->absorption.size());
    EXPECT_TRUE(same_bits(b.huang->absorption, t.huang->absorption));
}

// The sampling tables of `t` read back from its bytes, which must give back its Huang part bit
// for bit (nothing, with a test failure, when they do not load).
std::optional<SamplingTables> round_trip(const TableSet &t) {
    const std::vector<unsigned char> bytes = encode(t);
    const Expected<TableSet> back = decode_table_exr(bytes.data(), bytes.size());
    EXPECT_TRUE(back.ok()) << back.error().message;
    if (!back) return std::nullopt;
    expect_same_huang_part(back.value(), t);
    Expected<SamplingTables> sampling = SamplingTables::from(back.value());
    EXPECT_TRUE(sampling.ok()) << sampling.error().message;
    if (!sampling) return std::nullopt;
    return std::move(sampling).value();
}

// `t` with an f part of distinct values (a zero among them).
TableSet with_distinct_f(TableSet t) {
    auto h = std::make_shared<HuangTableSet>(*t.huang);
    for (std::size_t n = 0; n < 3 * h->values.size(); ++n) h->f.push_back(n == 4 ? 0.0f : 3.0f + 0.001f * float(n));
    t.huang = std::move(h);
    return t;
}

// `t` (with an f part) with an absorption part of 5 nodes, so that its second block of 4 has
// padding, and distinct values (a zero among them); 0.1 and 0.3 are not exact in decimal.
TableSet with_distinct_absorption(TableSet t) {
    auto h = std::make_shared<HuangTableSet>(*t.huang);
    h->absorption_nodes = {0.1f, 0.3f, 1.7f, 12.5f, 1000.0f};
    for (std::size_t n = 0; n < 5 * h->values.size(); ++n)
        h->absorption.push_back(n == 6 ? 0.0f : 7.0f + 0.001f * float(n));
    t.huang = std::move(h);
    return t;
}

TEST(HuangTableFile, RoundTripIsBitExact) {
    for (const TableSet &t : {distinct_tables(), distinct_tables(1, 1, 2, 1), distinct_tables(5, 4, 7, 3), baked()}) {
        const std::vector<unsigned char> bytes = encode(t);
        const Expected<TableSet> back = decode_table_exr(bytes.data(), bytes.size());
        ASSERT_TRUE(back.ok()) << back.error().message;
        expect_same_huang_part(back.value(), t);
    }
}

TEST(HuangTableFile, TheImageHoldsThePartWhereTheFormatSays) {
    const TableSet t = distinct_tables(3, 2, 4, 5);
    Image image = read_image(encode(t));
    const HuangTableSet &h = *t.huang;
    EXPECT_EQ(image.spec.get_string_attribute("hairis:parts"), "huang");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:model"), "huang2022");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:huang"), "row=0;theta_o=3;phi_o=2;theta_i=4;phi=5");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:parameters"), canonical_parameters(h.parameters));
    EXPECT_EQ(image.spec.find_attribute("hairis:theta_r_count"), nullptr);
    ASSERT_EQ(image.spec.width, 5);
    ASSERT_EQ(image.spec.height, 2 * 3 * 4);
    for (int q = 0; q < 2; ++q)
        for (int r = 0; r < 3; ++r)
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 5; ++j) {
                    const int y = (q * 3 + r) * 4 + i;
                    // values[((q·theta_o + r)·theta_i + i)·phi + j], the order HuangTable::create reads.
                    EXPECT_EQ(image.at(j, y, 0), h.values[size_t(((q * 3 + r) * 4 + i) * 5 + j)]) << q << r << i << j;
                    EXPECT_EQ(image.at(j, y, 1), 0.0f);
                    EXPECT_EQ(image.at(j, y, 2), 0.0f);
                    EXPECT_EQ(image.at(j, y, 3), 1.0f);
                }
}

// The multiple part (parts "huang,multiple"): round-trips bit for bit, lies after the Huang
// part with G = the value of (θ_r node r, θ_i cell i) in column k of n_h_values[k], and the
// sampling tables built from it have the multiple table (what dual scattering samples).
TEST(HuangTableFile, TheMultiplePartRoundTripsWhereTheFormatSays) {
    for (const TableSet &t : {distinct_with_multiple(), distinct_with_multiple(1, 1, 2, 1)}) {
        const std::optional<SamplingTables> sampling = round_trip(t);
        ASSERT_TRUE(sampling);
        ASSERT_TRUE(sampling->multiple && sampling->huang);
        EXPECT_EQ(sampling->multiple->n_h_values(), t.n_h_values);
    }
    const TableSet t = distinct_with_multiple();
    Image image = read_image(encode(t));
    EXPECT_EQ(image.spec.get_string_attribute("hairis:parts"), "huang,multiple");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:multiple"), "row=24;theta_r=3;theta_i=4");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:n_h_values"), "1,4");
    EXPECT_EQ(image.spec.find_attribute("hairis:theta_r_count"), nullptr);
    ASSERT_EQ(image.spec.width, 5);
    ASSERT_EQ(image.spec.height, 24 + 3 * 4);
    for (int r = 0; r < 3; ++r)
        for (int i = 0; i < 4; ++i)
            for (int x = 0; x < 5; ++x) {
                const int y = 24 + r * 4 + i;
                const bool cell = x < 2;
                EXPECT_EQ(image.at(x, y, 0), 0.0f);
                EXPECT_EQ(image.at(x, y, 1), cell ? t.multiple[size_t((r * 2 + x) * 4 + i)] : 0.0f) << r << i << x;
                EXPECT_EQ(image.at(x, y, 2), 0.0f);
                EXPECT_EQ(image.at(x, y, 3), cell ? 1.0f : 0.0f);
            }
    // A Huang part wider than n_h: the multiple part is padded; narrower: the Huang part is.
    Image narrow = read_image(encode(distinct_with_multiple(1, 1, 2, 1)));
    ASSERT_EQ(narrow.spec.width, 2);
    EXPECT_EQ(narrow.at(1, 0, 3), 0.0f);
    EXPECT_EQ(narrow.at(1, 2, 3), 1.0f);
}

// The f part (parts "huang,f" and "huang,f,multiple"): round-trips bit for bit, lies after the
// Huang part with RGB = the cell's f in the Huang part's column and row order, pushes the
// multiple part down by its rows, and the sampling tables built from it have the f table.
TEST(HuangTableFile, TheFPartRoundTripsWhereTheFormatSays) {
    for (const TableSet &t : {with_distinct_f(distinct_tables()), with_distinct_f(distinct_with_multiple()),
                              with_distinct_f(distinct_tables(1, 1, 2, 1)), baked()}) {
        ASSERT_TRUE(t.huang->has_f());
        const std::optional<SamplingTables> sampling = round_trip(t);
        ASSERT_TRUE(sampling);
        EXPECT_TRUE(sampling->huang->f);
    }
    const TableSet t = with_distinct_f(distinct_with_multiple());
    Image image = read_image(encode(t));
    EXPECT_EQ(image.spec.get_string_attribute("hairis:parts"), "huang,f,multiple");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:huang_f"), "row=24");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:multiple"), "row=48;theta_r=3;theta_i=4");
    ASSERT_EQ(image.spec.height, 24 + 24 + 3 * 4);
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 5; ++x) {
            const std::size_t n = std::size_t(y) * 5 + std::size_t(x);
            for (int c = 0; c < 3; ++c) EXPECT_EQ(image.at(x, 24 + y, c), t.huang->f[3 * n + std::size_t(c)]) << x << y;
            EXPECT_EQ(image.at(x, 24 + y, 3), 1.0f);
        }
    EXPECT_EQ(image.at(0, 48, 1), t.multiple[0]);
    EXPECT_EQ(read_image(encode(with_distinct_f(distinct_tables()))).spec.get_string_attribute("hairis:parts"), "huang,f");
}

// The f part's refinement is recorded when it is not 1 (files of the default bake stay readable
// by readers from before it) and comes back; out of range it is refused by name.
TEST(HuangTableFile, TheFPartsRefinementRoundTrips) {
    TableSet t = with_distinct_f(distinct_tables());
    EXPECT_EQ(read_image(encode(t)).spec.get_string_attribute("hairis:huang_f"), "row=24");
    auto h = std::make_shared<HuangTableSet>(*t.huang);
    h->f_refinement = 3;
    t.huang = h;
    const std::vector<unsigned char> bytes = encode(t);
    EXPECT_EQ(read_image(bytes).spec.get_string_attribute("hairis:huang_f"), "row=24;refinement=3");
    const Expected<TableSet> back = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back.value().huang->f_refinement, 3);
    const std::vector<unsigned char> plain = encode(with_distinct_f(distinct_tables()));
    EXPECT_EQ(decode_table_exr(plain.data(), plain.size()).value().huang->f_refinement, 1);
    expect_refused(tamper(t, [](Image &im) { im.spec.attribute("hairis:huang_f", "row=24;refinement=9"); }),
                   "refinement");
}

// A hand-built set can hold any refinement; the encoder refuses what the reader would.
TEST(HuangTableFile, TheEncoderRefusesARefinementOutOfRange) {
    TableSet t = with_distinct_f(distinct_tables());
    for (int k : {0, kMaxHuangFRefinement + 1}) {
        auto h = std::make_shared<HuangTableSet>(*t.huang);
        h->f_refinement = k;
        t.huang = h;
        const Expected<std::vector<unsigned char>> bytes = encode_table_exr(t);
        ASSERT_FALSE(bytes.ok()) << "refinement " << k;
        EXPECT_NE(bytes.error().message.find("f_refinement"), std::string::npos) << bytes.error().message;
    }
}

TEST(HuangTableFile, RefusesADamagedFPart) {
    const TableSet t = with_distinct_f(distinct_with_multiple());
    expect_refused(tamper(t, [](Image &im) { im.at(1, 25, 3) = 0.5f; }), "A must be 1 in the f part");
    expect_refused(tamper(t, [](Image &im) { im.at(2, 30, 1) = -1.0f; }), "f part");
    expect_refused(tamper(t, [](Image &im) { im.at(2, 30, 0) = std::numeric_limits<float>::quiet_NaN(); }), "NaN or infinity");
    expect_refused(tamper(t, [](Image &im) { im.spec.attribute("hairis:huang_f", "row=23"); }), "start at row 24");
    expect_refused(tamper(t, [](Image &im) { im.spec.erase_attribute("hairis:huang_f"); }),
                   "no string attribute hairis:huang_f");
    expect_refused(tamper(t, [](Image &im) { im.spec.attribute("hairis:parts", "huang,multiple"); }),
                   "names no f part");
    expect_refused(tamper(t, [](Image &im) { im.spec.attribute("hairis:parts", "huang,f"); }), "which has no multiple part");
}

// The absorption part (parts "huang,f,absorption" and "huang,f,absorption,multiple"):
// round-trips bit for bit, nodes included, and lies after the f part in blocks of the Huang
// part's rows, block b holding nodes 4b to 4b + 3 of the cell in R, G, B, A (0 past the last
// node); it pushes the multiple part down by its rows.
TEST(HuangTableFile, TheAbsorptionPartRoundTripsWhereTheFormatSays) {
    for (const TableSet &t : {with_distinct_absorption(with_distinct_f(distinct_tables())),
                              with_distinct_absorption(with_distinct_f(distinct_with_multiple())),
                              with_distinct_absorption(with_distinct_f(distinct_tables(1, 1, 2, 1)))}) {
        ASSERT_TRUE(t.huang->has_absorption());
        EXPECT_TRUE(round_trip(t));
    }
    EXPECT_EQ(read_image(encode(with_distinct_absorption(with_distinct_f(distinct_tables()))))
                  .spec.get_string_attribute("hairis:parts"),
              "huang,f,absorption");
    const TableSet t = with_distinct_absorption(with_distinct_f(distinct_with_multiple()));
    Image image = read_image(encode(t));
    EXPECT_EQ(image.spec.get_string_attribute("hairis:parts"), "huang,f,absorption,multiple");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:huang_f"), "row=24");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:huang_absorption"),
              "row=48;nodes=0.100000001,0.300000012,1.70000005,12.5,1000");
    EXPECT_EQ(image.spec.get_string_attribute("hairis:multiple"), "row=96;theta_r=3;theta_i=4");
    ASSERT_EQ(image.spec.width, 5);
    ASSERT_EQ(image.spec.height, 24 + 24 + 2 * 24 + 3 * 4);
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 5; ++x) {
            const std::size_t n = std::size_t(y) * 5 + std::size_t(x);
            EXPECT_EQ(image.at(x, 24 + y, 0), t.huang->f[3 * n]) << x << y;
            for (int b = 0; b < 2; ++b)
                for (int c = 0; c < 4; ++c) {
                    const int k = 4 * b + c;
                    EXPECT_EQ(image.at(x, 48 + 24 * b + y, c), k < 5 ? t.huang->absorption[5 * n + std::size_t(k)] : 0.0f)
                        << x << " " << y << " node " << k;
                }
        }
    EXPECT_EQ(image.at(0, 96, 1), t.multiple[0]);
}

// Damaged absorption parts are refused naming what is wrong (rows 48-71 hold nodes 0-3,
// rows 72-95 node 4 in R and padding in G, B, A).
TEST(HuangTableFile, RefusesADamagedAbsorptionPart) {
    const TableSet t = with_distinct_absorption(with_distinct_f(distinct_with_multiple()));
    auto with_absorption = [&](const std::string &value) {
        return tamper(t, [&](Image &im) { im.spec.attribute("hairis:huang_absorption", value); });
    };
    expect_refused(with_absorption("row=47;nodes=0.1,0.3,1.7,12.5,1000"),
                   "hairis:huang_absorption must start at row 48, after the f part");
    expect_refused(tamper(t, [](Image &im) { im.spec.erase_attribute("hairis:huang_absorption"); }),
                   "no string attribute hairis:huang_absorption");
    expect_refused(tamper(t, [](Image &im) { im.spec.attribute("hairis:parts", "huang,f,multiple"); }),
                   "hairis:parts names no absorption part, but the file has hairis:huang_absorption");
    expect_refused(tamper(t, [](Image &im) { im.spec.attribute("hairis:parts", "huang,absorption,multiple"); }),
                   "\"huang,f,absorption\", \"huang,multiple\", \"huang,f,multiple\" or \"huang,f,absorption,multiple\"");
    expect_refused(tamper(t, [](Image &im) { im.at(2, 75, 1) = 0.5f; }),
                   "the absorption part has 5 nodes, so its last block's channels past the last node (G, B, A) must "
                   "be 0 at pixel (2, 75)");
    expect_refused(tamper(t, [](Image &im) { im.at(1, 50, 2) = -1.0f; }),
                   "the Huang table's absorption part: entry 57 (cell 11, node 2) must be finite and >= 0");
    expect_refused(tamper(t, [](Image &im) { im.at(1, 73, 0) = std::numeric_limits<float>::infinity(); }),
                   "pixel (1, 73) holds NaN or infinity");
    expect_refused(with_absorption("row=48;nodes=0.5"),
                   "hairis:huang_absorption: nodes must be 2 to 32 numbers strictly increasing in (0, 1000]");
    expect_refused(with_absorption("row=48;nodes=0.1,0.3,0.3,12.5,1000"), "strictly increasing in (0, 1000]");
    expect_refused(with_absorption("row=48;nodes=0,0.3,1.7,12.5,1000"), "(got \"0,0.3,1.7,12.5,1000\")");
    expect_refused(with_absorption("row=48;nodes=0.1,0.3,1.7,12.5,2000"), "strictly increasing in (0, 1000]");
    expect_refused(with_absorption("row=48;nodes=0.1,0.3,1.7,12.5,x"), "strictly increasing in (0, 1000]");
    expect_refused(with_absorption("row=48;nodes=0.1,0.3,1.7,12.5,1000;k=5"), "unknown option \"k\"");
    // Four nodes fill one block: the image has a block of rows more than the attribute places.
    expect_refused(with_absorption("row=48;nodes=0.1,0.3,1.7,12.5"), "start at row 72, after the absorption part");
    expect_refused(tamper(with_distinct_absorption(with_distinct_f(distinct_tables())),
                          [](Image &im) { im.spec.attribute("hairis:huang_absorption", "row=48;nodes=0.1,0.3,1.7,12.5"); }),
                   "needs 5x72");
}

// The absorption part extends the f part: a set with the one but not the other is refused by
// HuangTableSet::validate(), whose message the encoder returns.
TEST(HuangTableFile, TheEncoderRefusesAnAbsorptionPartWithoutAnFPart) {
    TableSet t = with_distinct_absorption(with_distinct_f(distinct_tables()));
    auto h = std::make_shared<HuangTableSet>(*t.huang);
    h->f.clear();
    t.huang = h;
    const Expected<std::vector<unsigned char>> bytes = encode_table_exr(t);
    ASSERT_FALSE(bytes.ok());
    EXPECT_EQ(bytes.error().kind, ErrorKind::InvalidTable);
    EXPECT_NE(bytes.error().message.find("the Huang table's absorption part needs the f part beside it"),
              std::string::npos)
        << bytes.error().message;
}

TEST(HuangTableFile, RefusesADamagedMultiplePart) {
    expect_refused(tamper(distinct_with_multiple(), [](Image &im) { im.at(1, 25, 0) = 0.5f; }),
                   "R and B must be 0 and A must be 1 in the multiple part");
    expect_refused(tamper(distinct_with_multiple(), [](Image &im) { im.at(3, 26, 1) = 0.5f; }),
                   "pixel (3, 26) lies outside every part");
    expect_refused(tamper(distinct_with_multiple(), [](Image &im) { im.at(0, 27, 1) = -1.0f; }), "multiple table value");
    expect_refused(tamper(distinct_with_multiple(),
                          [](Image &im) { im.spec.attribute("hairis:multiple", "row=23;theta_r=3;theta_i=4"); }),
                   "start at row 24");
    expect_refused(tamper(distinct_with_multiple(),
                          [](Image &im) { im.spec.attribute("hairis:multiple", "row=24;theta_r=4;theta_i=4"); }),
                   "hairis:theta_r_nodes must hold 4 floats");
    expect_refused(tamper(distinct_with_multiple(), [](Image &im) { im.spec.erase_attribute("hairis:n_h_values"); }),
                   "hairis:n_h_values must give 1 to");
    expect_refused(tamper(distinct_with_multiple(), [](Image &im) { im.spec.erase_attribute("hairis:multiple"); }),
                   "no string attribute hairis:multiple");
    expect_refused(tamper(distinct_with_multiple(), [](Image &im) { im.spec.attribute("hairis:parts", "huang"); }),
                   "which has no multiple part");
    expect_refused(tamper(distinct_with_multiple(), [](Image &im) { im.spec.attribute("hairis:n_h_values", "4,1"); }),
                   "n_h values must be strictly increasing");
}

TEST(HuangTableFile, EncodingIsDeterministic) { EXPECT_EQ(encode(baked()), encode(baked())); }

// ---- The TABLE strategy from a loaded file -------------------------------------------------


std::shared_ptr<const Sampler> table_sampler(const SamplingTables &tables) {
    StrategyInputs in;
    in.huang = huang_fiber();
    in.tables = &tables;
    auto made = make_sampler(StrategyKind::Table, in);
    EXPECT_TRUE(made.ok()) << made.error().message;
    return made.ok() ? made.value() : nullptr;
}

// χ² of the TABLE strategy built from `tables` at views on and between the nodes.
void expect_table_strategy_exact(const SamplingTables &tables, const char *what) {
    const auto s = table_sampler(tables);
    ASSERT_TRUE(s);
    const HuangTable &table = *tables.huang->table;
    const std::pair<double, double> views[] = {{-33.75, 0.0}, {20.0, 0.7}, {-70.0, 2.2}};
    for (const auto &[theta_o, psi] : views) {
        const auto r = testing::chi2_huang_table_sampler(*s, table, theta_o, psi, 2 * int(std::size(views)));
        std::printf("[chi2] Huang table %s at theta_o %.2f, psi %.1f: %s\n", what, theta_o, psi, r.message.c_str());
        EXPECT_TRUE(r.passed) << what << " " << theta_o << ": " << r.message;
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << what << " " << theta_o;
        EXPECT_EQ(r.failed_samples, 0) << what << " " << theta_o;
    }
}

TEST(HuangTableFile, TheTableStrategyFromBytesIsExact) {
    const std::vector<unsigned char> bytes = encode(baked());
    const Expected<TableSet> loaded = decode_table_exr(bytes.data(), bytes.size());
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    const Expected<SamplingTables> tables = SamplingTables::from(loaded.value());
    ASSERT_TRUE(tables.ok()) << tables.error().message;
    EXPECT_FALSE(tables.value().direct);
    EXPECT_EQ(tables.value().model, "huang2022");
    expect_table_strategy_exact(tables.value(), "from bytes");
}

TEST(HuangTableFile, TheTableStrategyFromAFileIsExactAndSamplesTheBakedTable) {
    const std::string path =
        (std::filesystem::temp_directory_path() / ("hairis_huang_" + std::to_string(::getpid()) + ".exr")).string();
    ASSERT_FALSE(write_table_file(baked(), path));
    const Expected<TableSet> loaded = read_table_file(path);
    std::remove(path.c_str());
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    const SamplingTables from_file = SamplingTables::from(loaded.value()).value();
    expect_table_strategy_exact(from_file, "from a file");
    // The loaded sampler is the baked table's: the same density at every direction tried.
    const SamplingTables from_bake = SamplingTables::from(baked()).value();
    const auto a = table_sampler(from_file), b = table_sampler(from_bake);
    const FiberHit hit = huang_hit(12.0, 0.3);
    ScratchBuffer scratch;
    const FiberPoint &point = a->model()->prepare(hit, scratch);
    const SamplerPoint &pa = a->at(hit, &point, scratch), &pb = b->at(hit, &point, scratch);
    float largest = 0.0f, smallest = std::numeric_limits<float>::infinity();
    for (int k = 0; k < 500; ++k) {
        const Vec3 wi = direction_of(float(-1.5 + 3.0 * ((k * 37) % 500) / 500.0), float(-kPi + kTwoPi * k / 500.0));
        EXPECT_EQ(pa.pdf(wi), pb.pdf(wi)) << k;
        largest = std::max(largest, pa.pdf(wi));
        smallest = std::min(smallest, pa.pdf(wi));
    }
    EXPECT_GT(largest, 4.0f * smallest);  // not the uniform sphere
}

TEST(HuangTableFile, TablesOfAnotherFiberAreRefusedByTheStrategy) {
    const auto other = huang_fiber(0.5f);
    const TableSet t = bake_tables(*other, huang_parameters(other->params()), small_bake()).value();
    const std::vector<unsigned char> bytes = encode(t);
    const SamplingTables tables = SamplingTables::from(decode_table_exr(bytes.data(), bytes.size()).value()).value();
    StrategyInputs in;
    in.huang = huang_fiber();
    in.tables = &tables;
    const auto made = make_sampler(StrategyKind::Table, in);
    ASSERT_FALSE(made.ok());
    EXPECT_EQ(made.error().kind, ErrorKind::InvalidTable);
    EXPECT_NE(made.error().message.find("aspect_ratio=0.5"), std::string::npos) << made.error().message;
    // Huang tables are not far-field tables: a Chiang fiber or no fiber is refused by name.
    StrategyInputs none;
    none.tables = &tables;
    const auto far = make_sampler(StrategyKind::Table, none);
    ASSERT_FALSE(far.ok());
    EXPECT_NE(far.error().message.find("huang2022"), std::string::npos) << far.error().message;
}

// ---- Refusals --------------------------------------------------------------------------------

TEST(HuangTableFile, RefusesATruncatedFile) {
    const std::vector<unsigned char> bytes = encode(baked());
    for (size_t keep : {bytes.size() / 2, bytes.size() - 10}) {
        const std::vector<unsigned char> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(keep));
        const Expected<TableSet> t = decode_table_exr(cut.data(), cut.size());
        ASSERT_FALSE(t.ok()) << keep;
        EXPECT_EQ(t.error().kind, ErrorKind::InvalidTable) << t.error().message;
    }
}

TEST(HuangTableFile, RefusesAnAlteredValueWithAStaleHash) {
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.at(2, 3, 0) *= 1.5f; }, false), "hairis:pixel_sha1");
}

TEST(HuangTableFile, RefusesNaNInfinityAndNegativeValues) {
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.at(1, 2, 0) = std::nanf(""); }), "NaN");
    expect_refused(tamper(distinct_tables(), [](Image &im) {
                       im.at(4, 7, 0) = std::numeric_limits<float>::infinity();
                   }),
                   "NaN or infinity");
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.at(3, 5, 0) = -0.25f; }), "theta_o node 1");
}

TEST(HuangTableFile, RefusesNonZeroGOrBAndAOtherThanOne) {
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.at(0, 1, 1) = 0.5f; }), "G and B must be 0");
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.at(2, 0, 2) = 1.0f; }), "pixel (2, 0)");
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.at(4, 9, 3) = 0.0f; }), "A must be 1");
}

TEST(HuangTableFile, RefusesWrongCounts) {
    auto with_huang = [](const std::string &value) {
        return tamper(distinct_tables(), [&](Image &im) { im.spec.attribute("hairis:huang", value); });
    };
    // distinct_tables(): 3 θ_o × 2 φ_o × 4 θ_i × 5 φ, an image of 5 × 24.
    expect_refused(with_huang("row=0;theta_o=3;phi_o=2;theta_i=4;phi=6"), "needs 6x24");
    expect_refused(with_huang("row=0;theta_o=4;phi_o=2;theta_i=4;phi=5"), "needs 5x32");
    expect_refused(with_huang("row=0;theta_o=3;phi_o=1;theta_i=8;phi=5"), "hairis:huang_phi_o_nodes must hold 1");
    expect_refused(with_huang("row=2;theta_o=3;phi_o=2;theta_i=4;phi=5"), "row");
    expect_refused(with_huang("row=0;theta_o=3;phi_o=2;theta_i=4"), "phi");
    expect_refused(with_huang("row=0;theta_o=3;phi_o=2;theta_i=4;phi=5;n_h=2"), "n_h");
    expect_refused(with_huang("row=0;theta_o=0;phi_o=2;theta_i=4;phi=5"), "theta_o");
    expect_refused(tamper(distinct_tables(), [](Image &im) {
                       const float nodes[2] = {0.1f, 0.2f};
                       im.spec.attribute("hairis:huang_theta_o_nodes", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 2), nodes);
                   }),
                   "hairis:huang_theta_o_nodes must hold 3");
    expect_refused(tamper(distinct_tables(), [](Image &im) {
                       const float nodes[2] = {0.5f, 0.2f};
                       im.spec.attribute("hairis:huang_phi_o_nodes", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 2), nodes);
                   }),
                   "phi_o_nodes must be strictly increasing");
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.spec.erase_attribute("hairis:huang"); }),
                   "no string attribute hairis:huang");
}

TEST(HuangTableFile, RefusesAbsurdCountsBeforeAllocating) {
    // The claimed table would hold 2^36 cells; only the header says so.
    expect_refused(tamper(distinct_tables(),
                          [](Image &im) {
                              im.spec.attribute("hairis:huang", "row=0;theta_o=1024;phi_o=256;theta_i=4096;phi=64");
                          }),
                   "at most");
}

TEST(HuangTableFile, RefusesPartsAndModelsThatDoNotMatch) {
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.spec.attribute("hairis:model", "chiang2016"); }),
                   "model huang2022");
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.spec.attribute("hairis:parts", "far"); }),
                   "hairis:parts \"huang\"");
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.spec.attribute("hairis:parts", "far,huang"); }),
                   "hairis:parts");
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.spec.attribute("hairis:theta_r_count", 3); }),
                   "hairis:theta_r_count");
    expect_refused(tamper(distinct_tables(), [](Image &im) { im.spec.attribute("hairis:source", "gaussian"); }),
                   "source \"exact\"");
}

TEST(HuangTableFile, RefusesParametersThatAreNotAHuangFibers) {
    // A Chiang fiber's parameter list (no aspect ratio, no lobe multipliers) on a Huang part.
    expect_refused(tamper(distinct_tables(),
                          [](Image &im) {
                              im.spec.attribute("hairis:parameters",
                                                "sigma_a.r=0.2;sigma_a.g=0.5;sigma_a.b=1;roughness=0.3;"
                                                "radial_roughness=0.3;coat=0;ior=1.55;offset=0.03");
                          }),
                   "huang2022 tables record the parameters sigma_a_r,sigma_a_g");
    expect_refused(tamper(distinct_tables(),
                          [](Image &im) {
                              std::string p = im.spec.get_string_attribute("hairis:parameters");
                              im.spec.attribute("hairis:parameters", p.substr(0, p.rfind(';')));
                          }),
                   "secondary_reflection");
}

TEST(HuangTableFile, TheSetsRulesAreCheckedBeforeEncoding) {
    TableSet t = distinct_tables();
    t.phi_count = 4;
    t.direct.assign(4, 1.0f);
    auto far = encode_table_exr(t);
    ASSERT_FALSE(far.ok());
    EXPECT_NE(far.error().message.find("no direct far-field or near-field part"), std::string::npos)
        << far.error().message;
    TableSet partial = distinct_tables();
    partial.theta_r_nodes = {0.0f};
    auto half = encode_table_exr(partial);
    ASSERT_FALSE(half.ok());
    EXPECT_NE(half.error().message.find("theta_i_count"), std::string::npos) << half.error().message;
    TableSet counts = distinct_tables();
    counts.n_h_values = {1};
    auto no_nodes = encode_table_exr(counts);
    ASSERT_FALSE(no_nodes.ok());
    EXPECT_NE(no_nodes.error().message.find("some are missing"), std::string::npos) << no_nodes.error().message;
    TableSet other = distinct_tables();
    other.parameters[6].second = 0.5;  // aspect_ratio, not what the Huang part was baked for
    auto stale = encode_table_exr(other);
    ASSERT_FALSE(stale.ok());
    EXPECT_NE(stale.error().message.find("aspect_ratio=0.5"), std::string::npos) << stale.error().message;
    TableSet missing = distinct_tables();
    missing.huang = nullptr;
    auto none = encode_table_exr(missing);
    ASSERT_FALSE(none.ok());
    EXPECT_NE(none.error().message.find("Huang part"), std::string::npos) << none.error().message;
    TableSet chiang = distinct_tables();
    chiang.model = "chiang2016";
    auto foreign = encode_table_exr(chiang);
    ASSERT_FALSE(foreign.ok());
    EXPECT_NE(foreign.error().message.find("only for huang2022"), std::string::npos) << foreign.error().message;
}

}  // namespace
}  // namespace hairis
