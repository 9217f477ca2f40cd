// Writes the seed corpus of the table_reader target (fuzz/corpus/table_reader/): valid table
// files of format v2 (Chiang with a near part narrower and wider than the far part, with cone
// lobes and with extreme values; far-only Gaussian-source and Marschner files; huang2022 files
// of distinct values, with and without the multiple part) and, made from
// them with the library's encoder and OpenImageIO (or by editing bytes, for what OpenImageIO
// cannot write), one file per check of the reader, each named after what it breaks. Every
// pixel-level change keeps the hash right unless the hash is what it breaks, so the file
// reaches the check it names. The regression_* files that are raw byte crafts of the EXR
// header, refused by the header pre-check, are kept as committed and not written here.
// Deterministic: the same bytes on every run. Usage: write_table_seeds DIR.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fiber/fiber_spec.h"
#include "sampling/huang_table.h"
#include "sampling/near_field_table.h"
#include "tables/bake.h"
#include "tables/table_file.h"
#include "table_image.h"
#include "seed_writer.h"

namespace {

using namespace hairis;
using Bytes = std::vector<unsigned char>;

[[noreturn]] void fail(const std::string &what) {
    std::fprintf(stderr, "write_table_seeds: %s\n", what.c_str());
    std::exit(1);
}

template <typename T>
T ok(Expected<T> e, const std::string &what) {
    if (!e) fail(what + ": " + e.error().message);
    return std::move(e).value();
}

Bytes encode(const TableSet &t) { return ok(encode_table_exr(t), "encoding"); }

// ---- Pixel-level changes through OpenImageIO ---------------------------------------------------

using testing::Image;
using testing::rehash;

Image read(const Bytes &bytes) {
    std::optional<Image> image = testing::decode_image(bytes);
    if (!image) fail("cannot read back a table file");
    return std::move(*image);
}

Bytes write(const Image &image) {
    std::optional<Bytes> bytes = testing::encode_image(image);
    if (!bytes) fail("cannot write a tampered file");
    return std::move(*bytes);
}

// `bytes` re-encoded after `edit` changed the header or the pixels; the hash is made to match
// the pixels unless `keep_hash`.
Bytes tamper(const Bytes &bytes, const std::function<void(Image &)> &edit, bool keep_hash = false) {
    Image image = read(bytes);
    edit(image);
    if (!keep_hash) rehash(image);
    return write(image);
}

Bytes with_attribute(const Bytes &bytes, const std::string &name, const std::string &value) {
    return tamper(bytes, [&](Image &i) { i.spec.attribute(name, value); });
}

Bytes with_int_attribute(const Bytes &bytes, const std::string &name, int value) {
    return tamper(bytes, [&](Image &i) { i.spec.attribute(name, value); });
}

// ---- Byte-level changes -----------------------------------------------------------------------

// Where the value of header attribute `name` of type `type` starts (after its size field).
size_t attribute_value(const Bytes &bytes, const std::string &name, const std::string &type) {
    const std::string key = name + std::string(1, '\0') + type + std::string(1, '\0');
    const auto at = std::search(bytes.begin(), bytes.end(), key.begin(), key.end());
    if (at == bytes.end()) fail("no attribute " + name);
    return size_t(at - bytes.begin()) + key.size() + 4;
}

void put_int(Bytes &bytes, size_t at, int32_t value) {
    for (size_t b = 0; b < 4; ++b) bytes.at(at + b) = (unsigned char)(uint32_t(value) >> (8 * b));
}

struct Attribute {
    std::string name, type;
    Bytes value;
};

// The header's attributes, and where the header ends (past its terminating NUL).
std::pair<std::vector<Attribute>, size_t> parse_header(const Bytes &bytes) {
    std::vector<Attribute> attributes;
    size_t at = 8;
    auto text = [&]() {
        const auto end = std::find(bytes.begin() + std::ptrdiff_t(at), bytes.end(), 0);
        std::string s(bytes.begin() + std::ptrdiff_t(at), end);
        at = size_t(end - bytes.begin()) + 1;
        return s;
    };
    while (true) {
        Attribute a;
        a.name = text();
        if (a.name.empty()) return {attributes, at};
        a.type = text();
        int32_t size = 0;
        std::memcpy(&size, &bytes.at(at), sizeof size);
        at += sizeof size;
        a.value.assign(bytes.begin() + std::ptrdiff_t(at), bytes.begin() + std::ptrdiff_t(at + size_t(size)));
        at += size_t(size);
        attributes.push_back(std::move(a));
    }
}

Bytes int_value(int32_t v) {
    Bytes b(4);
    put_int(b, 0, v);
    return b;
}
Bytes box_value(int32_t x0, int32_t y0, int32_t x1, int32_t y1) {
    Bytes b;
    for (int32_t v : {x0, y0, x1, y1}) {
        const Bytes i = int_value(v);
        b.insert(b.end(), i.begin(), i.end());
    }
    return b;
}
Bytes floats_value(const std::vector<float> &values) {
    Bytes b(values.size() * sizeof(float));
    std::memcpy(b.data(), values.data(), b.size());
    return b;
}
Bytes string_value(const std::string &s) { return Bytes(s.begin(), s.end()); }

// The file with its header's attributes replaced (or added), and `offsets` zero chunk offsets
// inserted before its own offset table, so that a header claiming more scanline chunks than
// the file holds gets past OpenEXR's end-of-file check on the table.
Bytes rewrite_header(const Bytes &bytes, const std::vector<Attribute> &edits, size_t offsets) {
    auto [attributes, end] = parse_header(bytes);
    for (const Attribute &e : edits) {
        auto same = std::find_if(attributes.begin(), attributes.end(), [&](const Attribute &a) { return a.name == e.name; });
        if (same != attributes.end()) *same = e;
        else attributes.push_back(e);
    }
    Bytes out(bytes.begin(), bytes.begin() + 8);
    for (const Attribute &a : attributes) {
        out.insert(out.end(), a.name.begin(), a.name.end());
        out.push_back(0);
        out.insert(out.end(), a.type.begin(), a.type.end());
        out.push_back(0);
        const Bytes size = int_value(int32_t(a.value.size()));
        out.insert(out.end(), size.begin(), size.end());
        out.insert(out.end(), a.value.begin(), a.value.end());
    }
    out.push_back(0);
    out.insert(out.end(), offsets * 8, 0);
    out.insert(out.end(), bytes.begin() + std::ptrdiff_t(end), bytes.end());
    return out;
}

// ---- The valid tables --------------------------------------------------------------------------

// A huang2022 set of 2 φ_o × 3 θ_o nodes × 4 θ_i × 5 φ cells of distinct values (image rows
// 0..23) and, with `multiple`, the multiple part: 3 θ_r nodes × 4 θ_i cells (rows 24..35), n_h
// 1 and 4 (columns 0 and 1).
TableSet huang_set(bool multiple) {
    auto h = std::make_shared<HuangTableSet>();
    h->parameters = huang_parameters(HuangParams{});
    h->theta_o_nodes = {-1.0f, 0.1f, 1.2f};
    h->phi_o_nodes = {0.0f, 1.5707964f};
    h->theta_i_count = 4;
    h->phi_count = 5;
    for (int n = 0; n < 2 * 3 * 4 * 5; ++n) h->values.push_back(0.25f + 0.01f * float(n));
    TableSet t;
    t.model = "huang2022";
    t.source = "exact";
    t.parameters = h->parameters;
    t.huang = std::move(h);
    if (multiple) {
        t.theta_r_nodes = {-1.0f, 0.25f, 1.1f};
        t.theta_i_count = 4;
        t.n_h_values = {1, 4};
        for (int n = 0; n < 3 * 2 * 4; ++n) t.multiple.push_back(2.0f + 0.01f * float(n));
    }
    return t;
}

// huang_set with an f part (rows 24..47) and an absorption part of 5 nodes (rows 48..95, the
// last block padded), with the multiple part after them when `multiple`.
TableSet huang_absorption_set(bool multiple) {
    TableSet t = huang_set(multiple);
    auto h = std::make_shared<HuangTableSet>(*t.huang);
    for (std::size_t n = 0; n < 3 * h->values.size(); ++n) h->f.push_back(0.01f * float(n % 17));
    h->absorption_nodes = {0.015625f, 0.2f, 1.0f, 4.0f, 12.0f};
    for (std::size_t n = 0; n < 5 * h->values.size(); ++n) h->absorption.push_back(0.5f / float(1 + n % 5));
    t.huang = std::move(h);
    return t;
}

struct Chiang {
    std::shared_ptr<const ChiangFiber> fiber;
    std::vector<std::pair<std::string, double>> parameters;
};

// Blender's Principled Hair defaults (the fuzz target samples the near part with this fiber,
// rebuilt from the parameters a file records).
Chiang cycles_default() {
    const FiberSpec spec = ok(FiberSpec::preset("cycles-default"), "preset");
    Chiang c;
    c.fiber = std::make_shared<const ChiangFiber>(ok(ChiangFiber::create(ok(to_chiang_params(spec.node), "params")), "fiber"));
    c.parameters = ok(spec.parameters(), "parameters");
    return c;
}

TableSet bake(const FiberModel &model, const std::vector<std::pair<std::string, double>> &parameters, int theta_r,
              int theta_i, int phi, std::vector<int> n_h, const std::string &source = "exact") {
    BakeOptions o;
    o.theta_r_count = theta_r;
    o.theta_i_count = theta_i;
    o.phi_count = phi;
    o.n_h_values = std::move(n_h);
    o.source = source;
    TableSet t = ok(bake_tables(model, parameters, o), "bake");
    t.near_field = nullptr;  // set by the caller, at a seed's resolution
    return t;
}

// At a seed's coarse resolution Auto would draw every lobe from the cone, leaving the rows
// unread: the rows are the default here.
std::shared_ptr<const NearFieldData> near_part(const Chiang &c, int nodes, int cells,
                                               std::array<LobeSampling, 4> lobes = {LobeSampling::Table, LobeSampling::Table,
                                                                                    LobeSampling::Table, LobeSampling::Table}) {
    NearFieldTableOptions o;
    o.theta_o_nodes = nodes;
    o.theta_i_cells = cells;
    o.lobe_sampling = lobes;
    return ok(NearFieldTable::create(c.fiber, o), "near-field table").shared_data();
}

}  // namespace

int main(int argc, char **argv) {
    const char *folder = hairis::fuzz::seed_folder(argc, argv);
    if (!folder) return 2;
    hairis::fuzz::Seeds seeds;
    auto add = [&](const std::string &name, Bytes b) { seeds.emplace_back(name, std::move(b)); };

    const Chiang chiang = cycles_default();
    // 2 θ_r × 4 θ_i × 8 φ (image rows 0..7) and a near part of 3 θ_o nodes × 6 cells (rows
    // 8..19, columns 0..6; column 7 is the near rows' padding).
    TableSet narrow = bake(*chiang.fiber, chiang.parameters, 2, 4, 8, {1, 2});
    narrow.near_field = near_part(chiang, 3, 6);
    const Bytes chiang_file = encode(narrow);
    constexpr int kFarRows = 8;
    // 2 × 4 × 4 and a near part of 2 nodes × 12 cells: 13 columns, the far rows padded from 4.
    TableSet wide = bake(*chiang.fiber, chiang.parameters, 2, 4, 4, {1});
    wide.near_field = near_part(chiang, 2, 12);
    const Bytes wide_file = encode(wide);
    TableSet gaussian = bake(*chiang.fiber, chiang.parameters, 1, 2, 5, {1, 2, 4, 8, 16}, "gaussian");
    const FiberSpec blonde = ok(FiberSpec::preset("blonde"), "preset");
    const TableSet marschner = bake(*ok(blonde.create_model(), "Marschner"), ok(blonde.parameters(), "parameters"), 3, 2, 3, {1});
    const Bytes marschner_file = encode(marschner);

    // ---- Valid files ----
    add("chiang_2x4x8.exr", chiang_file);
    add("chiang_near_wider.exr", wide_file);
    {  // TT and the residual drawn from the fiber's cone at every node, R and TRT as Auto
       // chooses (the cone, at this resolution).
        TableSet t = narrow;
        t.near_field = near_part(chiang, 3, 6, {LobeSampling::Auto, LobeSampling::Cone, LobeSampling::Auto, LobeSampling::Cone});
        add("chiang_near_cone.exr", encode(t));
    }
    {  // Valid extremes: a lobe without mass (its row zero, its integral not), the largest
       // float as mass, edge and integral, subnormal edges, an edge of zero beside a positive one.
        TableSet t = narrow;
        auto n = std::make_shared<NearFieldData>(*narrow.near_field);
        std::fill(n->mass.begin() + 6, n->mass.begin() + 12, 0.0f);
        n->mass[14] = n->edge[16] = n->integral[2] = std::numeric_limits<float>::max();
        n->edge[17] = std::numeric_limits<float>::max();
        n->edge[21] = n->edge[22] = std::numeric_limits<float>::denorm_min();
        n->edge[29] = 0.0f;
        t.near_field = n;
        add("chiang_near_extreme.exr", encode(t));
    }
    add("gaussian_1x2x5.exr", encode(gaussian));
    add("marschner_3x2x3.exr", marschner_file);

    // ---- Not a (whole) table file ----
    add("empty_header_exr", {0x76, 0x2f, 0x31, 0x01, 0x02, 0x00, 0x00, 0x00, 0x00});
    add("magic_only", {0x76, 0x2f, 0x31, 0x01});
    {
        const std::string ppm = "P6\n2 2\n255\n";
        Bytes b(ppm.begin(), ppm.end());
        b.resize(23, 0);
        add("not_exr", b);
    }
    add("truncated_header", Bytes(chiang_file.begin(), chiang_file.begin() + 300));
    add("truncated_half", Bytes(chiang_file.begin(), chiang_file.begin() + std::ptrdiff_t(chiang_file.size() / 2)));
    add("truncated_last_byte", Bytes(chiang_file.begin(), chiang_file.end() - 1));
    // Cut inside the value of hairis:near: the attribute claims more bytes than the data holds.
    add("truncated_in_attribute",
        Bytes(chiang_file.begin(), chiang_file.begin() + std::ptrdiff_t(attribute_value(chiang_file, "hairis:near", "string") + 9)));
    {  // Two bytes of the first chunk's compressed data, one byte of the last chunk's.
        Bytes b = chiang_file;
        const size_t header_end = parse_header(b).second;
        uint64_t first_chunk = 0;
        std::memcpy(&first_chunk, &b.at(header_end), sizeof first_chunk);
        b.at(size_t(first_chunk) + 8 + 40) ^= 0x5a;
        b.at(size_t(first_chunk) + 8 + 41) ^= 0xa5;
        add("corrupt_compressed", b);
        Bytes c = chiang_file;
        c.at(c.size() - 39) ^= 0x55;
        add("corrupt_pixels", c);
    }
    {  // The first chunk offset 2^64 − 4: OpenEXR seeks before the buffer.
        Bytes b = chiang_file;
        const uint64_t offset = ~uint64_t(0) - 3;
        std::memcpy(&b.at(parse_header(b).second), &offset, sizeof offset);
        add("regression_chunk_offset_before_data", b);
    }

    // ---- The data window (the header pre-check) and counts the data does not hold ----
    {
        Bytes b = chiang_file;
        put_int(b, attribute_value(b, "dataWindow", "box2i") + 8, -8);  // x1 = −8: 7 columns fewer than none
        add("claims_negative_window.exr", b);
        Bytes c = chiang_file;
        put_int(c, attribute_value(c, "dataWindow", "box2i") + 4, 127);  // y0 past y1
        add("corrupt_data_window", c);
    }
    {  // 8 × 4096 × 4096 far cells and the near part: 4096 × 32780 pixels, over the limit.
        std::vector<float> nodes;
        for (int r = 0; r < 8; ++r) nodes.push_back(-1.5f + 0.4f * float(r));
        const int height = 8 * 4096 + 12;
        add("claims_128m_cells.exr",
            rewrite_header(chiang_file,
                           {{"dataWindow", "box2i", box_value(0, 0, 4095, height - 1)},
                            {"displayWindow", "box2i", box_value(0, 0, 4095, height - 1)},
                            {"hairis:theta_r_count", "int", int_value(8)},
                            {"hairis:theta_i_count", "int", int_value(4096)},
                            {"hairis:phi_count", "int", int_value(4096)},
                            {"hairis:theta_r_nodes", "floatvector", floats_value(nodes)},
                            {"hairis:near", "string", string_value("row=32768;theta_o=3;theta_i=6")}},
                           size_t(height + 15) / 16));
    }
    {  // 1 × 4096 × 4096 far cells and the near part, consistent and within the limits, in a
       // 3 KB file: the scanlines are missing, found band by band.
        const int height = 4096 + 12;
        add("claims_16m_cells.exr",
            rewrite_header(chiang_file,
                           {{"dataWindow", "box2i", box_value(0, 0, 4095, height - 1)},
                            {"displayWindow", "box2i", box_value(0, 0, 4095, height - 1)},
                            {"hairis:theta_r_count", "int", int_value(1)},
                            {"hairis:theta_i_count", "int", int_value(4096)},
                            {"hairis:phi_count", "int", int_value(4096)},
                            {"hairis:theta_r_nodes", "floatvector", floats_value({0.1f})},
                            {"hairis:near", "string", string_value("row=4096;theta_o=3;theta_i=6")}},
                           size_t(height + 15) / 16));
    }
    {  // θ_i count 2 → 66 by one bit: the far part no longer fits the image.
        Bytes b = marschner_file;
        b.at(attribute_value(b, "hairis:theta_i_count", "int")) ^= 0x40;
        add("corrupt_theta_i_count", b);
    }
    // θ_i count 5 with the near part moved to match: the image is 8x20, the metadata 8x22.
    add("theta_i_mismatch.exr", tamper(chiang_file, [](Image &i) {
            i.spec.attribute("hairis:theta_i_count", 5);
            i.spec.attribute("hairis:near", "row=10;theta_o=3;theta_i=6");
        }));

    // ---- The header's metadata ----
    add("version_3.exr", with_int_attribute(chiang_file, "hairis:format_version", 3));
    add("version_1.exr", tamper(encode(gaussian), [](Image &i) {  // as version 1 wrote files
            i.spec.attribute("hairis:format_version", 1);
            i.spec.erase_attribute("hairis:parts");
        }));
    add("no_version.exr", tamper(chiang_file, [](Image &i) { i.spec.erase_attribute("hairis:format_version"); }));
    add("unknown_model.exr", with_attribute(chiang_file, "hairis:model", "pbrt"));
    add("parameter_nan.exr", with_attribute(chiang_file, "hairis:parameters", "roughness=nan"));
    add("n_h_decreasing.exr", with_attribute(chiang_file, "hairis:n_h_values", "2,1"));
    add("n_h_more_than_phi.exr", with_attribute(chiang_file, "hairis:n_h_values", "1,2,3,4,5,6,7,8,9"));
    add("sha1_mismatch.exr", tamper(chiang_file, [](Image &i) { i.spec.attribute("hairis:pixel_sha1", 0); }, true));
    add("three_channels.exr", tamper(chiang_file, [](Image &i) {
            std::vector<float> rgb;
            for (size_t p = 0; p < i.px.size(); p += 4) rgb.insert(rgb.end(), i.px.begin() + std::ptrdiff_t(p), i.px.begin() + std::ptrdiff_t(p + 3));
            i.px = rgb;
            i.spec.nchannels = 3;
            i.spec.channelnames = {"R", "G", "B"};
            i.spec.alpha_channel = -1;
        }, true));
    add("half_pixels.exr", tamper(chiang_file, [](Image &i) { i.spec.set_format(OIIO::TypeDesc::HALF); }, true));
    add("far_band_inconsistent.exr", tamper(chiang_file, [](Image &i) { i.at(1, 2, 1) += 0.5f; }));

    // ---- The parts ----
    add("parts_unknown.exr", with_attribute(chiang_file, "hairis:parts", "far,near,far"));
    add("parts_far_with_near_rows.exr", with_attribute(chiang_file, "hairis:parts", "far"));
    add("parts_near_on_far_only_file.exr", tamper(marschner_file, [](Image &i) {
            i.spec.attribute("hairis:model", "chiang2016");
            i.spec.attribute("hairis:parts", "far,near");
            i.spec.attribute("hairis:near", "row=6;theta_o=2;theta_i=4");
        }));
    add("near_on_marschner.exr", with_attribute(chiang_file, "hairis:model", "marschner2003"));
    add("near_missing.exr", tamper(chiang_file, [](Image &i) { i.spec.erase_attribute("hairis:near"); }));
    add("near_not_a_string.exr", tamper(chiang_file, [](Image &i) {
            i.spec.erase_attribute("hairis:near");
            i.spec.attribute("hairis:near", 8);
        }));
    add("near_garbled.exr", with_attribute(chiang_file, "hairis:near", "row=8;theta_o=3;theta_i"));
    add("near_unknown_option.exr", with_attribute(chiang_file, "hairis:near", "row=8;theta_o=3;theta_i=6;cone=1"));
    add("near_row_wrong.exr", with_attribute(chiang_file, "hairis:near", "row=7;theta_o=3;theta_i=6"));
    add("near_counts_wrong.exr", with_attribute(chiang_file, "hairis:near", "row=8;theta_o=4;theta_i=6"));
    add("near_cells_wrong.exr", with_attribute(chiang_file, "hairis:near", "row=8;theta_o=3;theta_i=7"));
    add("near_counts_absurd.exr", with_attribute(chiang_file, "hairis:near", "row=8;theta_o=2147483647;theta_i=1073741824"));
    add("near_counts_largest.exr", with_attribute(chiang_file, "hairis:near", "row=8;theta_o=1024;theta_i=4096"));

    // ---- The near part's pixels (rows 8..19; columns 0..5 cells, 6 the upper edge) ----
    add("near_far_padding_nonzero.exr", tamper(wide_file, [](Image &i) { i.at(6, 1, 2) = 0.5f; }));
    add("near_padding_nonzero.exr", tamper(chiang_file, [](Image &i) { i.at(7, kFarRows + 1, 0) = 1.0f; }));
    add("near_b_not_constant.exr", tamper(chiang_file, [](Image &i) { i.at(3, kFarRows + 2, 2) *= 1.5f; }));
    add("near_a_not_constant.exr", tamper(chiang_file, [](Image &i) { i.at(6, kFarRows + 5, 3) = 1.0f - i.at(6, kFarRows + 5, 3); }));
    add("near_cone_flag_half.exr", tamper(chiang_file, [](Image &i) {
            for (int k = 0; k <= 6; ++k) i.at(k, kFarRows + 3, 3) = 0.5f;
        }));
    add("near_r_in_last_column.exr", tamper(chiang_file, [](Image &i) { i.at(6, kFarRows + 4, 0) = 1e-3f; }));
    add("near_mass_nan.exr", tamper(chiang_file, [](Image &i) { i.at(2, kFarRows + 6, 0) = std::numeric_limits<float>::quiet_NaN(); }));
    add("near_edge_inf.exr", tamper(chiang_file, [](Image &i) { i.at(6, kFarRows + 7, 1) = std::numeric_limits<float>::infinity(); }));
    add("near_mass_negative.exr", tamper(chiang_file, [](Image &i) { i.at(4, kFarRows + 9, 0) = -1e-6f; }));
    add("near_edge_negative.exr", tamper(chiang_file, [](Image &i) { i.at(0, kFarRows + 10, 1) = -0.5f; }));
    add("near_integral_negative.exr", tamper(chiang_file, [](Image &i) {
            for (int k = 0; k <= 6; ++k) i.at(k, kFarRows + 11, 2) = -i.at(k, kFarRows + 11, 2) - 1.0f;
        }));
    add("near_hash_mismatch.exr", tamper(chiang_file, [](Image &i) { i.at(5, kFarRows + 11, 1) *= 1.0001f; }, true));

    // ---- Huang files: the Huang part alone and with the multiple part ----
    const Bytes huang_file = encode(huang_set(false)), huang_multiple_file = encode(huang_set(true));
    add("huang_2x3x4x5.exr", huang_file);
    add("huang_multiple_3x4.exr", huang_multiple_file);
    add("huang_g_nonzero.exr", tamper(huang_file, [](Image &i) { i.at(2, 5, 1) = 0.5f; }));
    add("huang_part_value_negative.exr", tamper(huang_file, [](Image &i) { i.at(4, 7, 0) = -1.0f; }));
    add("huang_multiple_r_nonzero.exr", tamper(huang_multiple_file, [](Image &i) { i.at(1, 25, 0) = 0.5f; }));
    add("huang_multiple_padding_nonzero.exr", tamper(huang_multiple_file, [](Image &i) { i.at(3, 30, 3) = 1.0f; }));
    add("huang_multiple_value_nan.exr", tamper(huang_multiple_file, [](Image &i) {
            i.at(0, 33, 1) = std::numeric_limits<float>::quiet_NaN();
        }));
    add("huang_multiple_row_wrong.exr", with_attribute(huang_multiple_file, "hairis:multiple", "row=23;theta_r=3;theta_i=4"));
    add("huang_multiple_counts_absurd.exr",
        with_attribute(huang_multiple_file, "hairis:multiple", "row=24;theta_r=1024;theta_i=4096"));
    add("huang_multiple_n_h_missing.exr", tamper(huang_multiple_file, [](Image &i) { i.spec.erase_attribute("hairis:n_h_values"); }));
    add("huang_parts_without_multiple.exr", with_attribute(huang_multiple_file, "hairis:parts", "huang"));
    add("huang_parts_multiple_missing.exr", with_attribute(huang_file, "hairis:parts", "huang,multiple"));

    // ---- Huang files with the f and absorption parts ----
    const Bytes absorption_file = encode(huang_absorption_set(false));
    add("huang_absorption_5_nodes.exr", absorption_file);
    add("huang_absorption_multiple.exr", encode(huang_absorption_set(true)));
    add("huang_absorption_padding_nonzero.exr", tamper(absorption_file, [](Image &i) { i.at(2, 90, 3) = 0.5f; }));
    add("huang_absorption_nodes_absurd.exr",
        with_attribute(absorption_file, "hairis:huang_absorption", "row=48;nodes=1e30,2e30"));
    add("huang_absorption_parts_without_f.exr", with_attribute(absorption_file, "hairis:parts", "huang,absorption"));

    return hairis::fuzz::write_seeds(folder, seeds);
}
