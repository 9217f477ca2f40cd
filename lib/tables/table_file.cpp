#include "tables/table_file.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/hash.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <utility>

#include "core/math.h"
#include "core/options.h"
#include "sampling/huang_table.h"
#include "tables/bake.h"

namespace hairis {

namespace {

using OIIO::TypeDesc;

constexpr int kChannels = 4;
// The channels in order, for naming them in messages.
constexpr const char *kChannelNames[kChannels] = {"R", "G", "B", "A"};

std::string sha1_of(const std::vector<float> &pixels) {
    OIIO::SHA1 sha(pixels.data(), pixels.size() * sizeof(float));
    return sha.digest();
}

std::string join_ints(const std::vector<int> &values) {
    std::string out;
    for (size_t i = 0; i < values.size(); ++i) out += (i ? "," : "") + std::to_string(values[i]);
    return out;
}

// Floats printed with format_number, so that each reads back to the identical float.
std::string join_floats(const std::vector<float> &values) {
    std::string out;
    for (size_t i = 0; i < values.size(); ++i) out += (i ? "," : "") + format_number(values[i]);
    return out;
}

// The optional parts of a huang2022 file, as hairis:parts names them.
struct HuangParts {
    bool f = false, absorption = false, multiple = false;
};

// The hairis:parts values of huang2022 files: the Huang part, then the f part, the absorption
// part (which extends the f part, so only after it) and the multiple part, each optional.
constexpr std::pair<const char *, HuangParts> kHuangParts[] = {
    {"huang", {false, false, false}},          {"huang,f", {true, false, false}},
    {"huang,f,absorption", {true, true, false}}, {"huang,multiple", {false, false, true}},
    {"huang,f,multiple", {true, false, true}},   {"huang,f,absorption,multiple", {true, true, true}}};

std::optional<HuangParts> huang_parts_of(const std::string &parts) {
    for (const auto &[name, huang_parts] : kHuangParts)
        if (parts == name) return huang_parts;
    return std::nullopt;
}

// "\"huang\", \"huang,f\", ... or \"huang,f,absorption,multiple\"", for messages.
std::string huang_parts_list() {
    std::string out;
    const size_t count = std::size(kHuangParts);
    for (size_t i = 0; i < count; ++i)
        out += std::string(i == 0 ? "" : i + 1 == count ? " or " : ", ") + "\"" + kHuangParts[i].first + "\"";
    return out;
}

// OIIO 2.4.7's IOMemReader takes any seek and checks a read's end as size + offset in
// unsigned arithmetic, so a "negative" offset (OpenEXR seeks wherever a damaged chunk table
// points) wraps past the check and copies from before the buffer. This reader answers a read
// outside the buffer with 0 bytes, which OpenEXR reports as a truncated file.
class BoundedMemReader final : public OIIO::Filesystem::IOMemReader {
public:
    using IOMemReader::IOMemReader;
    size_t read(void *buf, size_t size) override {
        const size_t n = pread(buf, size, m_pos);
        m_pos += int64_t(n);
        return n;
    }
    size_t pread(void *buf, size_t size, int64_t offset) override {
        const size_t total = m_buf.size();
        if (offset < 0 || uint64_t(offset) >= total) return 0;
        return IOMemReader::pread(buf, std::min(size, total - size_t(offset)), offset);
    }
};

// The image of a table file: as wide as the far part's φ cells or the near part's θ_i cells
// and their upper edge, whichever is wider, and at most kMaxTableCells pixels in all.
constexpr long long kMaxImageWidth = kMaxTableAxisCells + 1;
constexpr long long kMaxImagePixels = kMaxTableCells;

std::string image_limits() {
    return std::to_string(kMaxImageWidth) + " columns and " + std::to_string(kMaxImagePixels) + " pixels";
}

// Column band k of the G channel: columns [k·phi/K, (k+1)·phi/K).
int band_of_column(int j, int phi_count, int bands) { return int((long long)j * bands / phi_count); }

// The absorption part's blocks: one per 4 nodes (R, G, B, A), as many as K nodes need.
long long absorption_blocks(int nodes) { return (nodes + kChannels - 1) / kChannels; }

// Where each part lies in the image (table_file.h): the far part's rows first, then the
// near-field part's; the width is the widest part's, narrower rows padded with zeros.
struct Layout {
    int far_rows = 0, near_rows = 0, near_cols = 0;
    // huang2022: the Huang part, its f part (as many rows), its absorption part (as many rows
    // per 4 nodes), then the multiple part.
    long long huang_rows = 0, f_rows = 0, absorption_rows = 0, multiple_rows = 0;
    long long width = 0, height = 0;
    static Layout of(const TableSet &t) {
        Layout l;
        if (const HuangTableSet *h = t.huang.get()) {
            l.huang_rows = (long long)h->phi_o_count() * h->theta_o_count() * h->theta_i_count;
            l.f_rows = h->has_f() ? l.huang_rows : 0;
            l.absorption_rows = absorption_blocks(h->absorption_count()) * l.huang_rows;
            l.multiple_rows = t.has_multiple() ? (long long)t.theta_r_count() * t.theta_i_count : 0;
            l.width = std::max<long long>(h->phi_count, t.has_multiple() ? (long long)t.n_h_values.size() : 0);
            l.height = l.huang_rows + l.f_rows + l.absorption_rows + l.multiple_rows;
            return l;
        }
        l.far_rows = t.theta_r_count() * t.theta_i_count;
        if (t.near_field) {
            l.near_rows = t.near_field->rows();
            l.near_cols = t.near_field->theta_i_cells + 1;
        }
        l.width = std::max<long long>(t.phi_count, l.near_cols);
        l.height = (long long)l.far_rows + l.near_rows;
        return l;
    }
};

// The Huang part: row (q·theta_o_count + r)·theta_i_count + i, column j holds R = the value of
// φ_o node q, θ_o node r, cell (i, j); G = B = 0, A = 1. The values' order is exactly this.
// The f part after it (when baked): row huang_rows + the Huang part's row, same column, holds
// R, G, B = the f part's RGB of that cell, A = 1. The absorption part after it (when baked):
// row huang_rows + f_rows + b·huang_rows + the Huang part's row, same column, holds nodes 4b to
// 4b + 3 of that cell in R, G, B, A (0 past the last node). The multiple part after those: row
// huang_rows + f_rows + absorption_rows + r·theta_i_count + i, column k holds G = the multiple
// table at θ_r node r, n_h value k, θ_i cell i; R = B = 0, A = 1. Padding is 0.
std::vector<float> huang_pixels_of(const TableSet &t) {
    const HuangTableSet &h = *t.huang;
    const Layout l = Layout::of(t);
    const size_t width = size_t(l.width);
    std::vector<float> px(width * size_t(l.height) * kChannels, 0.0f);
    const size_t huang_width = size_t(h.phi_count);
    for (size_t n = 0; n < h.values.size(); ++n) {
        float *p = &px[((n / huang_width) * width + n % huang_width) * kChannels];
        p[0] = h.values[n];
        p[3] = 1.0f;
        if (!h.has_f()) continue;
        float *q = &px[((size_t(l.huang_rows) + n / huang_width) * width + n % huang_width) * kChannels];
        for (int c = 0; c < 3; ++c) q[c] = h.f[3 * n + size_t(c)];
        q[3] = 1.0f;
        const size_t nodes = size_t(h.absorption_count()), huang_row = n / huang_width;
        for (size_t k = 0; k < nodes; ++k) {
            const size_t row = size_t(l.huang_rows + l.f_rows) + (k / kChannels) * size_t(l.huang_rows) + huang_row;
            px[(row * width + n % huang_width) * kChannels + k % kChannels] = h.absorption[nodes * n + k];
        }
    }
    const int bands = int(t.n_h_values.size());
    for (int r = 0; r < (t.has_multiple() ? t.theta_r_count() : 0); ++r)
        for (int i = 0; i < t.theta_i_count; ++i)
            for (int k = 0; k < bands; ++k) {
                const size_t row = size_t(l.huang_rows + l.f_rows + l.absorption_rows) +
                                   size_t(r) * size_t(t.theta_i_count) + size_t(i);
                float *p = &px[(row * width + size_t(k)) * kChannels];
                p[1] = t.multiple_at(r, k, i);
                p[3] = 1.0f;
            }
    return px;
}

std::vector<float> pixels_of(const TableSet &t) {
    if (t.huang) return huang_pixels_of(t);
    const Layout l = Layout::of(t);
    const size_t width = size_t(l.width);
    const int bands = int(t.n_h_values.size());
    std::vector<float> px(width * size_t(l.height) * kChannels, 0.0f);
    for (int r = 0; r < t.theta_r_count(); ++r) {
        for (int i = 0; i < t.theta_i_count; ++i) {
            const size_t row = size_t(r) * t.theta_i_count + i;
            for (int j = 0; j < t.phi_count; ++j) {
                float *p = &px[(row * width + size_t(j)) * kChannels];
                p[0] = t.direct_at(r, i, j);
                p[1] = bands ? t.multiple_at(r, band_of_column(j, t.phi_count, bands), i) : 0.0f;
                p[2] = 0.0f;
                p[3] = 1.0f;
            }
        }
    }
    if (const NearFieldData *n = t.near_field.get()) {
        const int cells = n->theta_i_cells;
        for (int row = 0; row < n->rows(); ++row)
            for (int k = 0; k <= cells; ++k) {
                float *p = &px[((size_t(l.far_rows) + size_t(row)) * width + size_t(k)) * kChannels];
                p[0] = k < cells ? n->mass[size_t(row) * size_t(cells) + size_t(k)] : 0.0f;
                p[1] = n->edge[size_t(row) * size_t(cells + 1) + size_t(k)];
                p[2] = n->integral[size_t(row)];
                p[3] = float(n->cone[size_t(row)]);
            }
    }
    return px;
}

std::string pixel_name(long long x, long long y) { return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")"; }

Error file_error(const std::string &what) { return Error{"hairis table: " + what, ErrorKind::InvalidTable}; }

// The options that string attribute `name` holds.
Expected<OptionReader> attribute_options(const OIIO::ImageSpec &spec, const char *name) {
    Expected<OptionReader> reader = OptionReader::parse(spec.get_string_attribute(name), name);
    if (!reader) return file_error(reader.error().message);
    return reader;
}

// The options of string attribute `name`, which the file's parts require (`missing` says so).
Expected<OptionReader> required_options(const OIIO::ImageSpec &spec, const char *name,
                                        const std::string &missing) {
    const OIIO::ParamValue *attribute = spec.find_attribute(name);
    if (!attribute || attribute->type() != TypeDesc::STRING) return file_error(missing);
    return attribute_options(spec, name);
}

// A padding pixel: outside every part, so all four channels must be 0.
Status check_padding(const float *p, size_t x, size_t y) {
    if (p[0] != 0.0f || p[1] != 0.0f || p[2] != 0.0f || p[3] != 0.0f)
        return file_error(pixel_name((long long)x, (long long)y) + " lies outside every part and must be 0");
    return std::nullopt;
}

// The size OpenEXR reads for an attribute of a fixed-size type whatever its size field says
// (0: a variable-size or unknown type, read as `size` bytes).
int fixed_attribute_size(const std::string &type) {
    static const std::pair<const char *, int> sizes[] = {
        {"int", 4},    {"float", 4},     {"double", 8},     {"v2i", 8},        {"v2f", 8},
        {"v2d", 16},   {"v3i", 12},      {"v3f", 12},       {"v3d", 24},       {"box2i", 16},
        {"box2f", 16}, {"m33f", 36},     {"m33d", 72},      {"m44f", 64},      {"m44d", 128},
        {"rational", 8}, {"timecode", 8}, {"keycode", 28},  {"chromaticities", 32},
        {"tiledesc", 9}, {"compression", 1}, {"lineOrder", 1}, {"envmap", 1},
        {"deepImageState", 1}};
    for (const auto &[name, bytes] : sizes)
        if (type == name) return bytes;
    return 0;
}

// A first look at the EXR header, before OpenEXR reads it: OpenEXR allocates what an
// attribute's size field, a string vector's entry, a preview or the data window claims (a
// string attribute of 1.7 GB in a 2 KB buffer, a window of 2^31 rows whose offset table it
// allocates) before finding the data missing, and reads fixed-size types at their own size,
// so that a wrong size field makes it read the rest of the header out of step. Table files
// are single-part scanline images whose attributes are consistent, lie inside the buffer and
// whose window fits the table limits; anything else is refused here (found by fuzzing).
Status check_exr_header(const unsigned char *data, size_t size) {
    auto read_int = [&](size_t at) {
        int32_t v = 0;
        for (int b = 3; b >= 0; --b) v = int32_t(uint32_t(v) << 8 | data[at + size_t(b)]);
        return v;
    };
    if (size < 8 || data[0] != 0x76 || data[1] != 0x2f || data[2] != 0x31 || data[3] != 0x01)
        return file_error("not a readable OpenEXR file (no OpenEXR magic number)");
    const uint32_t flags = uint32_t(read_int(4)) & ~0xffu;
    constexpr uint32_t kLongNames = 0x400, kNonImage = 0x800, kMultiPart = 0x1000;
    if (flags & (kNonImage | kMultiPart))
        return file_error("a multi-part or deep OpenEXR file is not a table file");
    const size_t max_name = flags & kLongNames ? 255 : 31;
    size_t at = 8;
    auto read_name = [&](std::string &name) -> Status {
        const void *end = std::memchr(data + at, 0, std::min(size - at, max_name + 1));
        if (!end) return file_error("the OpenEXR header is truncated or corrupt (attribute name)");
        name.assign(reinterpret_cast<const char *>(data + at), size_t(static_cast<const unsigned char *>(end) - (data + at)));
        at += name.size() + 1;
        return std::nullopt;
    };
    std::string name, type;
    while (true) {
        if (at >= size) return file_error("the OpenEXR header is truncated");
        if (Status s = read_name(name)) return s;
        if (name.empty()) break;  // the end of the header
        if (at >= size) return file_error("the OpenEXR header is truncated");
        if (Status s = read_name(type)) return s;
        if (size - at < 4) return file_error("the OpenEXR header is truncated");
        const int32_t length = read_int(at);
        at += 4;
        if (length < 0 || size_t(length) > size - at)
            return file_error("OpenEXR attribute \"" + name + "\" claims " + std::to_string(length) +
                              " bytes; the data holds " + std::to_string(size - at));
        const int fixed = fixed_attribute_size(type);
        if (fixed != 0 && length != fixed)
            return file_error("OpenEXR attribute \"" + name + "\" of type " + type + " has size " +
                              std::to_string(length) + " (a " + type + " has " + std::to_string(fixed) + ")");
        if (type == "stringvector") {
            for (size_t in = 0; in < size_t(length);) {
                if (size_t(length) - in < 4) return file_error("OpenEXR attribute \"" + name + "\" is corrupt");
                const int32_t entry = read_int(at + in);
                in += 4;
                if (entry < 0 || size_t(entry) > size_t(length) - in)
                    return file_error("OpenEXR attribute \"" + name + "\" has an entry larger than itself");
                in += size_t(entry);
            }
        }
        if (type == "chlist") {
            // Entries of a name and 16 bytes, up to an empty name that must end the attribute.
            size_t in = 0;
            while (true) {
                const size_t left = size_t(length) - in;
                const void *end = std::memchr(data + at + in, 0, std::min(left, max_name + 1));
                if (!end) return file_error("OpenEXR attribute \"" + name + "\": a channel entry is corrupt");
                const size_t name_size = size_t(static_cast<const unsigned char *>(end) - (data + at + in));
                in += name_size + 1;
                if (name_size == 0) break;
                if (size_t(length) - in < 16)
                    return file_error("OpenEXR attribute \"" + name + "\": a channel entry is truncated");
                in += 16;
            }
            if (in != size_t(length))
                return file_error("OpenEXR attribute \"" + name + "\": the channel list does not fill its size");
        }
        if (type == "preview") {
            // width × height RGBA bytes after the two sizes (unsigned: no overflow).
            const uint64_t width = length >= 8 ? uint32_t(read_int(at)) : 0;
            const uint64_t height = length >= 8 ? uint32_t(read_int(at + 4)) : 0;
            if (length < 8 || width * height != (uint64_t(length) - 8) / 4 || (length - 8) % 4 != 0)
                return file_error("OpenEXR attribute \"" + name + "\": the preview's size does not match its data");
        }
        if (name == "dataWindow") {
            if (type != "box2i" || length != 16) return file_error("dataWindow must be a box2i");
            const long long width = (long long)read_int(at + 8) - read_int(at) + 1;
            const long long height = (long long)read_int(at + 12) - read_int(at + 4) + 1;
            if (width < 1 || height < 1 || width > kMaxImageWidth || width * height > kMaxImagePixels)
                return file_error("the image is " + std::to_string(width) + "x" + std::to_string(height) +
                                  " pixels; a table has at most " + image_limits());
        }
        at += size_t(length);
    }
    return std::nullopt;
}

Expected<std::vector<unsigned char>> write_exr(const OIIO::ImageSpec &spec, const std::vector<float> &px) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create("openexr");
    if (!out) return file_error("OpenImageIO has no OpenEXR writer: " + OIIO::geterror());
    if (!out->set_ioproxy(&proxy) || !out->open("tables.exr", spec) ||
        !out->write_image(TypeDesc::FLOAT, px.data()) || !out->close())
        return file_error("encoding the EXR failed: " + out->geterror());
    return bytes;
}

// Reads every scanline in bands of rows, so memory grows with the data the file really holds
// (a small file whose header claims a large table fails at its first missing scanline instead
// of after allocating the whole table), and checks the pixels against hairis:pixel_sha1 and
// that every value is finite.
Expected<std::vector<float>> read_pixels(OIIO::ImageInput &in) {
    const OIIO::ImageSpec &spec = in.spec();
    const size_t width = size_t(spec.width), height = size_t(spec.height);
    constexpr size_t kBandRows = 64;
    std::vector<float> px, band;
    OIIO::SHA1 hash;
    for (size_t y = 0; y < height; y += kBandRows) {
        const size_t rows = std::min(kBandRows, height - y);
        band.resize(rows * width * kChannels);
        if (!in.read_scanlines(0, 0, int(y), int(y + rows), 0, 0, kChannels, TypeDesc::FLOAT, band.data()))
            return file_error("the pixel data cannot be read (truncated or corrupt): " + in.geterror());
        hash.append(band.data(), band.size() * sizeof(float));
        px.insert(px.end(), band.begin(), band.end());
    }
    if (spec.get_string_attribute("hairis:pixel_sha1") != hash.digest())
        return file_error("pixel data does not match its hash hairis:pixel_sha1 (file modified or corrupt)");
    for (size_t n = 0; n < px.size(); ++n)
        if (!std::isfinite(px[n]))
            return file_error(pixel_name((long long)(n / kChannels % width), (long long)(n / kChannels / width)) +
                              " holds NaN or infinity");
    return px;
}

// A float array attribute of exactly `count` values, else an error naming it.
Expected<std::vector<float>> float_array(const OIIO::ImageSpec &spec, const char *name, int count) {
    const OIIO::ParamValue *a = spec.find_attribute(name);
    if (!a || a->type().basetype != TypeDesc::FLOAT || a->type().basevalues() * size_t(a->nvalues()) != size_t(count))
        return file_error(std::string(name) + " must hold " + std::to_string(count) + " floats");
    const float *values = static_cast<const float *>(a->data());
    return std::vector<float>(values, values + count);
}

// The n_h values attribute "1,2,..." (absent: none).
Expected<std::vector<int>> n_h_values_of(const OIIO::ImageSpec &spec) {
    std::vector<int> values;
    const std::string text = spec.get_string_attribute("hairis:n_h_values");
    if (text.empty()) return values;
    std::stringstream in_text(text);
    std::string entry;
    while (std::getline(in_text, entry, ',')) {
        char *end = nullptr;
        const long v = std::strtol(entry.c_str(), &end, 10);
        if (entry.empty() || *end != '\0' || v < 1 || v > 1024)
            return file_error("hairis:n_h_values must be integers in [1, 1024] (got \"" + text + "\")");
        values.push_back(int(v));
    }
    return values;
}

// A Huang file's rows, as its attributes place them: the Huang part, its f part (as many rows,
// or none), its absorption part (as many rows per 4 nodes, or none) and the multiple part
// after them.
struct HuangLayout {
    int theta_o = 0, phi_o = 0, theta_r = 0;
    long long rows = 0, f_rows = 0;  // φ_o × θ_o × θ_i each
    long long absorption_rows = 0;
    long long width = 0, height = 0;
};

// A Huang file has no Chiang part, and no multiple part's attributes unless its parts name one.
Status check_huang_parts(const OIIO::ImageSpec &spec, bool multiple) {
    for (const char *far : {"hairis:theta_r_count", "hairis:theta_i_count", "hairis:phi_count", "hairis:near"})
        if (spec.find_attribute(far))
            return file_error(std::string("a huang2022 file has no direct far-field or near-field part, but it has ") +
                              far);
    if (!multiple)
        for (const char *part : {"hairis:theta_r_nodes", "hairis:n_h_values", "hairis:multiple"})
            if (spec.find_attribute(part))
                return file_error(std::string("hairis:parts is \"huang\", which has no multiple part, but the file "
                                              "has ") + part);
    return std::nullopt;
}

// hairis:huang: the Huang part's axes, within the size limits.
Status read_huang_axes(const OIIO::ImageSpec &spec, HuangTableSet &h, HuangLayout &layout) {
    Expected<OptionReader> reader = required_options(
        spec, "hairis:huang",
        "hairis:parts is \"huang\" but there is no string attribute hairis:huang "
        "(\"row=0;theta_o=...;phi_o=...;theta_i=...;phi=...\")");
    if (!reader) return reader.error();
    int row = -1;
    reader.value().field("row", row, 0, 0);
    reader.value().field("theta_o", layout.theta_o, 1, kMaxThetaRNodes);
    reader.value().field("phi_o", layout.phi_o, 1, kMaxPhiONodes);
    reader.value().field("theta_i", h.theta_i_count, 1, kMaxTableAxisCells);
    reader.value().field("phi", h.phi_count, 1, kMaxTableAxisCells);
    if (Status e = reader.value().finish()) return file_error(e->message);
    if (row != 0 || layout.theta_o == 0 || layout.phi_o == 0 || h.theta_i_count == 0 || h.phi_count == 0)
        return file_error("hairis:huang must give row=0, theta_o, phi_o, theta_i and phi");
    layout.rows = (long long)layout.phi_o * layout.theta_o * h.theta_i_count;
    if (layout.rows * h.phi_count > kMaxTableCells ||
        HuangTable::bytes_needed(layout.theta_o, layout.phi_o, h.theta_i_count, h.phi_count) > kMaxSamplingTableBytes)
        return file_error("hairis:huang claims " + std::to_string(layout.rows * h.phi_count) +
                          " cells; a Huang table has at most " + std::to_string(kMaxTableCells) + " cells and " +
                          std::to_string(kMaxSamplingTableBytes) + " bytes");
    layout.width = h.phi_count;
    layout.height = layout.rows;
    return std::nullopt;
}

// hairis:huang_f: there exactly when the parts name an f part, starting after the Huang part.
Status read_huang_f(const OIIO::ImageSpec &spec, bool with_f, HuangLayout &layout, int &refinement) {
    if (with_f != (spec.find_attribute("hairis:huang_f") != nullptr))
        return file_error(with_f ? "hairis:parts names an f part but there is no string attribute hairis:huang_f "
                                   "(\"row=...\")"
                                 : "hairis:parts names no f part, but the file has hairis:huang_f");
    if (!with_f) return std::nullopt;
    Expected<OptionReader> fr = attribute_options(spec, "hairis:huang_f");
    if (!fr) return fr.error();
    int f_row = -1;
    fr.value().field("row", f_row, 0, kMaxTableCells);
    fr.value().field("refinement", refinement, 1, kMaxHuangFRefinement);
    if (Status e = fr.value().finish()) return file_error(e->message);
    if (f_row != layout.rows)
        return file_error("hairis:huang_f must start at row " + std::to_string(layout.rows) + ", after the Huang part");
    layout.f_rows = layout.rows;
    layout.height += layout.f_rows;
    return std::nullopt;
}

// hairis:huang_absorption: there exactly when the parts name an absorption part, starting after
// the f part, with 2 to kMaxHuangAbsorptionNodes nodes strictly increasing in
// (0, kMaxHuangAbsorption].
Status read_huang_absorption(const OIIO::ImageSpec &spec, bool with_absorption, HuangLayout &layout,
                             std::vector<float> &nodes) {
    const std::string name = "hairis:huang_absorption";
    if (!with_absorption) {
        if (spec.find_attribute(name)) return file_error("hairis:parts names no absorption part, but the file has " + name);
        return std::nullopt;
    }
    Expected<OptionReader> reader =
        required_options(spec, name.c_str(),
                         "hairis:parts names an absorption part but there is no string attribute " + name +
                             " (\"row=...;nodes=...\")");
    if (!reader) return reader.error();
    int row = -1;
    std::string text;
    reader.value().field("row", row, 0, kMaxTableCells);
    reader.value().field("nodes", text);
    const int count = text.empty() ? 0 : int(std::count(text.begin(), text.end(), ',')) + 1;
    const std::string allowed = "2 to " + std::to_string(kMaxHuangAbsorptionNodes) +
                                " numbers strictly increasing in (0, " + format_number(kMaxHuangAbsorption) +
                                "] separated by ','";
    if (count < 2 || count > kMaxHuangAbsorptionNodes)
        return file_error(name + ": nodes must be " + allowed + " (got \"" + text + "\")");
    nodes.assign(size_t(count), 0.0f);
    bool valid = !reader.value().read("nodes", nodes.data(), count, 0.0, double(kMaxHuangAbsorption));
    for (size_t k = 0; k < nodes.size(); ++k)
        valid = valid && nodes[k] > 0.0f && (k == 0 || nodes[k] > nodes[k - 1]);
    if (!valid) return file_error(name + ": nodes must be " + allowed + " (got \"" + text + "\")");
    if (Status e = reader.value().finish()) return file_error(e->message);
    const long long first = layout.rows + layout.f_rows;
    if (row != first)
        return file_error(name + " must start at row " + std::to_string(first) + ", after the f part");
    layout.absorption_rows = absorption_blocks(count) * layout.rows;
    layout.height += layout.absorption_rows;
    return std::nullopt;
}

// hairis:multiple with its θ_r nodes and n_h values, starting after the f and absorption parts.
Status read_huang_multiple(const OIIO::ImageSpec &spec, TableSet &t, HuangLayout &layout) {
    Expected<OptionReader> mr = required_options(
        spec, "hairis:multiple",
        "hairis:parts is \"huang,multiple\" but there is no string attribute hairis:multiple "
        "(\"row=...;theta_r=...;theta_i=...\")");
    if (!mr) return mr.error();
    int multiple_row = -1;
    mr.value().field("row", multiple_row, 0, kMaxTableCells);
    mr.value().field("theta_r", layout.theta_r, 1, kMaxThetaRNodes);
    mr.value().field("theta_i", t.theta_i_count, 2, kMaxTableAxisCells);
    if (Status e = mr.value().finish()) return file_error(e->message);
    const long long first = layout.rows + layout.f_rows + layout.absorption_rows;
    const char *before = layout.absorption_rows > 0 ? ", after the absorption part"
                         : layout.f_rows > 0        ? ", after the f part"
                                                    : ", after the Huang part";
    if (multiple_row != first || layout.theta_r == 0 || t.theta_i_count == 0)
        return file_error("hairis:multiple must give theta_r and theta_i and start at row " + std::to_string(first) +
                          before);
    Expected<std::vector<float>> nodes = float_array(spec, "hairis:theta_r_nodes", layout.theta_r);
    if (!nodes) return nodes.error();
    t.theta_r_nodes = std::move(nodes).value();
    Expected<std::vector<int>> n_h = n_h_values_of(spec);
    if (!n_h) return n_h.error();
    t.n_h_values = std::move(n_h).value();
    if (t.n_h_values.empty() || t.n_h_values.size() > size_t(kMaxStrandCounts))
        return file_error("hairis:n_h_values must give 1 to " + std::to_string(kMaxStrandCounts) +
                          " strand counts for the multiple part");
    layout.width = std::max<long long>(layout.width, (long long)t.n_h_values.size());
    layout.height += (long long)layout.theta_r * t.theta_i_count;
    return std::nullopt;
}

// The pixels into the Huang part (R), its f part (RGB), its absorption part (RGBA per 4 nodes)
// and the multiple part (G per n_h), with every unused channel and the padding checked.
Status unpack_huang_pixels(const std::vector<float> &px, const HuangLayout &layout, HuangTableSet &h, TableSet &t) {
    const size_t w = size_t(layout.width), huang_width = size_t(h.phi_count), bands = t.n_h_values.size();
    const size_t rows = size_t(layout.rows), first_absorption = size_t(layout.rows + layout.f_rows);
    const size_t first_multiple = first_absorption + size_t(layout.absorption_rows);
    const size_t nodes = size_t(h.absorption_count());
    h.values.resize(rows * huang_width);
    if (layout.f_rows > 0) h.f.resize(3 * h.values.size());
    h.absorption.resize(nodes * h.values.size());
    t.multiple.assign(size_t(t.theta_r_count()) * bands * size_t(t.theta_i_count), 0.0f);
    for (size_t y = 0; y < size_t(layout.height); ++y)
        for (size_t x = 0; x < w; ++x) {
            const float *p = &px[(y * w + x) * kChannels];
            const bool in_huang = y < rows && x < huang_width;
            const bool in_f = y >= rows && y < first_absorption && x < huang_width;
            const bool in_absorption = y >= first_absorption && y < first_multiple && x < huang_width;
            const bool in_multiple = y >= first_multiple && x < bands;
            if (in_absorption) {
                const size_t block = (y - first_absorption) / rows;
                const size_t n = ((y - first_absorption) % rows) * huang_width + x;
                for (size_t c = 0; c < size_t(kChannels); ++c) {
                    const size_t k = block * kChannels + c;
                    if (k < nodes) {
                        h.absorption[nodes * n + k] = p[c];
                    } else if (p[c] != 0.0f) {
                        std::string unused;
                        for (size_t u = nodes % kChannels; u < size_t(kChannels); ++u)
                            unused += std::string(unused.empty() ? "" : ", ") + kChannelNames[u];
                        return file_error("the absorption part has " + std::to_string(nodes) +
                                          " nodes, so its last block's channels past the last node (" + unused +
                                          ") must be 0 at " + pixel_name((long long)x, (long long)y));
                    }
                }
            } else if (in_f) {
                if (p[3] != 1.0f)
                    return file_error("A must be 1 in the f part at " + pixel_name((long long)x, (long long)y));
                const size_t n = (y - rows) * huang_width + x;
                for (size_t c = 0; c < 3; ++c) h.f[3 * n + c] = p[c];
            } else if (!in_huang && !in_multiple) {
                if (Status s = check_padding(p, x, y)) return s;
            } else if (in_huang) {
                if (p[1] != 0.0f || p[2] != 0.0f || p[3] != 1.0f)
                    return file_error("G and B must be 0 and A must be 1 in the Huang part at " +
                                      pixel_name((long long)x, (long long)y));
                h.values[y * huang_width + x] = p[0];
            } else {
                if (p[0] != 0.0f || p[2] != 0.0f || p[3] != 1.0f)
                    return file_error("R and B must be 0 and A must be 1 in the multiple part at " +
                                      pixel_name((long long)x, (long long)y));
                const size_t r = (y - first_multiple) / size_t(t.theta_i_count);
                const size_t i = (y - first_multiple) % size_t(t.theta_i_count);
                t.multiple[(r * bands + x) * size_t(t.theta_i_count) + i] = p[1];
            }
        }
    return std::nullopt;
}

// The Huang part (parts "huang"), its f part ("huang,f"), its absorption part
// ("huang,f,absorption") and the multiple part after them (the same with ",multiple"): the
// layout of huang_pixels_of, sizes checked before the pixels are read.
Expected<TableSet> decode_huang(OIIO::ImageInput &in, TableSet t, HuangParts parts) {
    const OIIO::ImageSpec &spec = in.spec();
    auto h = std::make_shared<HuangTableSet>();
    HuangLayout layout;
    if (Status s = check_huang_parts(spec, parts.multiple)) return *s;
    if (Status s = read_huang_axes(spec, *h, layout)) return *s;
    if (Status s = read_huang_f(spec, parts.f, layout, h->f_refinement)) return *s;
    if (Status s = read_huang_absorption(spec, parts.absorption, layout, h->absorption_nodes)) return *s;
    if (parts.multiple) {
        if (Status s = read_huang_multiple(spec, t, layout)) return *s;
    }
    if (Status s = TableImageSize{layout.width, layout.height}.validate()) return file_error(s->message);
    if (spec.width != layout.width || spec.height != layout.height || spec.depth != 1 || spec.x != 0 || spec.y != 0)
        return file_error("image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                          " but the metadata needs " + std::to_string(layout.width) + "x" +
                          std::to_string(layout.height));
    Expected<std::vector<float>> theta_o_nodes = float_array(spec, "hairis:huang_theta_o_nodes", layout.theta_o);
    if (!theta_o_nodes) return theta_o_nodes.error();
    Expected<std::vector<float>> phi_o_nodes = float_array(spec, "hairis:huang_phi_o_nodes", layout.phi_o);
    if (!phi_o_nodes) return phi_o_nodes.error();
    h->theta_o_nodes = std::move(theta_o_nodes).value();
    h->phi_o_nodes = std::move(phi_o_nodes).value();

    Expected<std::vector<float>> px = read_pixels(in);
    in.close();
    if (!px) return px.error();
    if (Status s = unpack_huang_pixels(px.value(), layout, *h, t)) return *s;
    h->parameters = t.parameters;
    t.huang = std::move(h);
    if (Status s = t.validate()) return *s;
    return t;
}

}  // namespace

std::string table_file_fingerprint(const void *data, size_t size) {
    const OIIO::farmhash::uint128_t h = OIIO::farmhash::Fingerprint128(static_cast<const char *>(data), size);
    char hex[33];
    std::snprintf(hex, sizeof hex, "%016llx%016llx", (unsigned long long)OIIO::farmhash::Uint128High64(h),
                  (unsigned long long)OIIO::farmhash::Uint128Low64(h));
    return hex;
}

Expected<std::vector<unsigned char>> encode_table_exr(const TableSet &t) {
    if (Status s = t.validate()) return *s;
    const Layout layout = Layout::of(t);
    // Each part is within its limits, but a narrow far part of many rows padded to a wide
    // near part's width may not be: checked before the image is allocated.
    if (Status s = TableImageSize{layout.width, layout.height}.validate()) return file_error(s->message);
    const std::vector<float> px = pixels_of(t);

    OIIO::ImageSpec spec(int(layout.width), int(layout.height), kChannels, TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "A"};
    spec.alpha_channel = 3;
    spec.attribute("compression", "zip");
    // OpenImageIO stamps the current time unless told otherwise; a fixed stamp keeps the
    // bytes a function of the tables alone (deterministic bakes).
    spec.attribute("DateTime", "1970:01:01 00:00:00");
    spec.attribute("hairis:format_version", kTableFormatVersion);
    spec.attribute("hairis:model", t.model);
    spec.attribute("hairis:source", t.source);
    spec.attribute("hairis:parameters", canonical_parameters(t.parameters));
    if (const HuangTableSet *h = t.huang.get()) {
        spec.attribute("hairis:parts", std::string("huang") + (h->has_f() ? ",f" : "") +
                                           (h->has_absorption() ? ",absorption" : "") +
                                           (t.has_multiple() ? ",multiple" : ""));
        if (h->has_f()) {
            // The refinement is written only when not 1, so that readers from before it read
            // the default bake's files.
            std::vector<std::pair<std::string, std::string>> f_options = {{"row", std::to_string(layout.huang_rows)}};
            if (h->f_refinement != 1) f_options.push_back({"refinement", std::to_string(h->f_refinement)});
            spec.attribute("hairis:huang_f", format_options(f_options));
        }
        if (h->has_absorption())
            spec.attribute("hairis:huang_absorption",
                           format_options({{"row", std::to_string(layout.huang_rows + layout.f_rows)},
                                           {"nodes", join_floats(h->absorption_nodes)}}));
        if (t.has_multiple()) {
            const long long multiple_row = layout.huang_rows + layout.f_rows + layout.absorption_rows;
            spec.attribute("hairis:multiple", format_options({{"row", std::to_string(multiple_row)},
                                                              {"theta_r", std::to_string(t.theta_r_count())},
                                                              {"theta_i", std::to_string(t.theta_i_count)}}));
            spec.attribute("hairis:theta_r_nodes", TypeDesc(TypeDesc::FLOAT, t.theta_r_count()),
                           t.theta_r_nodes.data());
            spec.attribute("hairis:n_h_values", join_ints(t.n_h_values));
        }
        spec.attribute("hairis:huang", format_options({{"row", "0"},
                                                       {"theta_o", std::to_string(h->theta_o_count())},
                                                       {"phi_o", std::to_string(h->phi_o_count())},
                                                       {"theta_i", std::to_string(h->theta_i_count)},
                                                       {"phi", std::to_string(h->phi_count)}}));
        spec.attribute("hairis:huang_theta_o_nodes", TypeDesc(TypeDesc::FLOAT, h->theta_o_count()),
                       h->theta_o_nodes.data());
        spec.attribute("hairis:huang_phi_o_nodes", TypeDesc(TypeDesc::FLOAT, h->phi_o_count()), h->phi_o_nodes.data());
        spec.attribute("hairis:pixel_sha1", sha1_of(px));
        return write_exr(spec, px);
    }
    spec.attribute("hairis:theta_r_count", t.theta_r_count());
    spec.attribute("hairis:theta_i_count", t.theta_i_count);
    spec.attribute("hairis:phi_count", t.phi_count);
    spec.attribute("hairis:theta_r_nodes", TypeDesc(TypeDesc::FLOAT, t.theta_r_count()),
                   t.theta_r_nodes.data());
    spec.attribute("hairis:n_h_values", join_ints(t.n_h_values));
    std::string parts = "far";
    if (t.near_field) {
        parts += ",near";
        spec.attribute("hairis:near", format_options({{"row", std::to_string(layout.far_rows)},
                                                      {"theta_o", std::to_string(t.near_field->theta_o_nodes)},
                                                      {"theta_i", std::to_string(t.near_field->theta_i_cells)}}));
    }
    spec.attribute("hairis:parts", parts);
    spec.attribute("hairis:pixel_sha1", sha1_of(px));
    return write_exr(spec, px);
}

namespace {

// The steps of decode_table_exr, in its order.

// The format version, the channels and the pixel type of an opened table file.
Status check_table_spec(const OIIO::ImageSpec &spec) {
    const int version = spec.get_int_attribute("hairis:format_version", -1);
    if (version == -1) return file_error("no hairis:format_version attribute: not a hairis table file");
    if (version == 1)
        return file_error("format version 1 (baked by hairis 0.1) lacks what this build samples (the near-field "
                          "tables); re-bake the tables (the Bake button, or hairis-bake bake)");
    if (version != kTableFormatVersion)
        return file_error("format version " + std::to_string(version) + " is not supported (this build reads version " +
                          std::to_string(kTableFormatVersion) + ")");
    if (spec.nchannels != kChannels || spec.channelnames != std::vector<std::string>{"R", "G", "B", "A"})
        return file_error("expected 4 channels R, G, B, A (got " + std::to_string(spec.nchannels) + ")");
    if (spec.format != TypeDesc::FLOAT)
        return file_error("pixels must be 32-bit float (got " + std::string(spec.format.c_str()) + ")");
    return std::nullopt;
}

// hairis:parameters ("name=value;...") into t.parameters.
Status read_parameters(const OIIO::ImageSpec &spec, TableSet &t) {
    std::stringstream param_text(spec.get_string_attribute("hairis:parameters"));
    std::string item;
    while (std::getline(param_text, item, ';')) {
        const size_t eq = item.find('=');
        char *end = nullptr;
        const double v = eq == std::string::npos ? 0.0 : std::strtod(item.c_str() + eq + 1, &end);
        if (eq == std::string::npos || eq == 0 || end == item.c_str() + eq + 1 || *end != '\0')
            return file_error("hairis:parameters entry \"" + item + "\" is not name=value");
        t.parameters.emplace_back(item.substr(0, eq), v);
    }
    return std::nullopt;
}

// The near part's resolution from hairis:near, which must start right after the far part.
Status read_near_header(const OIIO::ImageSpec &spec, long long far_rows, NearFieldData &near) {
    const OIIO::ParamValue *near_attribute = spec.find_attribute("hairis:near");
    if (!near_attribute) return file_error("hairis:parts is \"far,near\" but there is no hairis:near attribute");
    if (near_attribute->type() != TypeDesc::STRING)
        return file_error("hairis:near must be a string \"row=...;theta_o=...;theta_i=...\" (got a " +
                          std::string(near_attribute->type().c_str()) + ")");
    Expected<OptionReader> reader = attribute_options(spec, "hairis:near");
    if (!reader) return reader.error();
    int row = -1;
    reader.value().field("row", row, 0, kMaxTableCells);
    reader.value().field("theta_o", near.theta_o_nodes, 2, kMaxThetaRNodes);
    reader.value().field("theta_i", near.theta_i_cells, 4, kMaxTableAxisCells);
    if (Status e = reader.value().finish()) return file_error(e->message);
    if (row != far_rows || near.theta_o_nodes == 0 || near.theta_i_cells == 0)
        return file_error("hairis:near must give theta_o and theta_i and start at row " + std::to_string(far_rows) +
                          ", after the far part");
    return std::nullopt;
}

// The far part: R direct, G the n_h bands, B = 0, A = 1; zero padding beyond phi_count.
Status read_far_part(const std::vector<float> &px, size_t width, long long far_rows, TableSet &t) {
    const int bands = int(t.n_h_values.size());
    if (bands > t.phi_count) return file_error("more n_h values than phi columns");
    t.direct.resize(size_t(t.theta_r_count()) * t.theta_i_count * t.phi_count);
    t.multiple.assign(size_t(t.theta_r_count()) * bands * t.theta_i_count, 0.0f);
    for (size_t row = 0; row < size_t(far_rows); ++row) {
        const int r = int(row / size_t(t.theta_i_count)), i = int(row % size_t(t.theta_i_count));
        for (size_t j = 0; j < width; ++j) {
            const float *p = &px[(row * width + j) * kChannels];
            if (j >= size_t(t.phi_count)) {
                if (Status s = check_padding(p, j, row)) return s;
                continue;
            }
            t.direct[row * size_t(t.phi_count) + j] = p[0];
            if (bands) {
                const int k = band_of_column(int(j), t.phi_count, bands);
                float &m = t.multiple[(size_t(r) * bands + k) * t.theta_i_count + i];
                const bool band_start = j == 0 || band_of_column(int(j) - 1, t.phi_count, bands) != k;
                if (band_start) m = p[1];
                else if (p[1] != m)
                    return file_error("G channel differs inside the n_h band at " + pixel_name((long long)j, (long long)row));
            }
            if (p[2] != 0.0f || p[3] != 1.0f)
                return file_error("B must be 0 and A must be 1 at " + pixel_name((long long)j, (long long)row));
        }
    }
    return std::nullopt;
}

// The near part: R cell mass, G M_p at the cell's lower edge, B the lobe integral and A the
// cone flag, both constant along the row; the last column holds only the upper edge.
Status read_near_part(const std::vector<float> &px, size_t width, long long far_rows, NearFieldData &near) {
    auto pixel = [&](size_t row, size_t j) { return &px[(row * width + j) * kChannels]; };
    const size_t cells = size_t(near.theta_i_cells), rows = size_t(near.rows());
    near.mass.resize(rows * cells);
    near.edge.resize(rows * (cells + 1));
    near.integral.resize(rows);
    near.cone.resize(rows);
    for (size_t q = 0; q < rows; ++q) {
        const size_t row = size_t(far_rows) + q;
        near.integral[q] = pixel(row, 0)[2];
        const float cone = pixel(row, 0)[3];
        if (cone != 0.0f && cone != 1.0f)
            return file_error("A (the cone flag) must be 0 or 1 at " + pixel_name(0, (long long)row));
        near.cone[q] = cone == 1.0f;
        for (size_t k = 0; k < width; ++k) {
            const float *p = pixel(row, k);
            if (k > cells) {
                if (Status s = check_padding(p, k, row)) return s;
                continue;
            }
            if (p[2] != near.integral[q] || p[3] != cone)
                return file_error("B and A must be constant along a near-field row at " + pixel_name((long long)k, (long long)row));
            if (k < cells) near.mass[q * cells + k] = p[0];
            else if (p[0] != 0.0f) return file_error("R must be 0 in the near part's last column at " + pixel_name((long long)k, (long long)row));
            near.edge[q * (cells + 1) + k] = p[1];
        }
    }
    return std::nullopt;
}

}  // namespace

Expected<TableSet> decode_table_exr(const void *data, size_t size) {
    if (data == nullptr || size == 0) return file_error("the data is empty, not an EXR file");
    if (Status s = check_exr_header(static_cast<const unsigned char *>(data), size)) return *s;
    BoundedMemReader proxy(data, size);
    auto in = OIIO::ImageInput::create("openexr");
    if (!in) return file_error("OpenImageIO has no OpenEXR reader: " + OIIO::geterror());
    // OIIO 2.4 takes the in-memory proxy through the open() configuration.
    OIIO::ImageSpec config, opened;
    void *proxy_pointer = &proxy;
    config.attribute("oiio:ioproxy", TypeDesc::PTR, &proxy_pointer);
    if (!in->open("tables.exr", opened, config)) {
        std::string why = in->geterror();
        return file_error("not a readable OpenEXR file" + (why.empty() ? std::string() : ": " + why));
    }
    const OIIO::ImageSpec &spec = in->spec();
    if (Status s = check_table_spec(spec)) return *s;

    TableSet t;
    t.model = spec.get_string_attribute("hairis:model");
    t.source = spec.get_string_attribute("hairis:source");
    if (Status s = read_parameters(spec, t)) return *s;
    const std::string parts = spec.get_string_attribute("hairis:parts");
    if (const std::optional<HuangParts> huang_parts = huang_parts_of(parts)) {
        if (t.model != "huang2022")
            return file_error("hairis:parts \"" + parts + "\" is for model huang2022 (got \"" + t.model + "\")");
        return decode_huang(*in, std::move(t), *huang_parts);
    }
    if (t.model == "huang2022")
        return file_error("huang2022 tables have hairis:parts " + huang_parts_list() + " (got \"" + parts + "\")");
    const int theta_r_count = spec.get_int_attribute("hairis:theta_r_count", 0);
    t.theta_i_count = spec.get_int_attribute("hairis:theta_i_count", 0);
    t.phi_count = spec.get_int_attribute("hairis:phi_count", 0);
    // Checked before anything is allocated: the header alone can claim any size.
    if (Status s = TableResolution{theta_r_count, t.theta_i_count, t.phi_count}.validate())
        return file_error(s->message);
    if (parts != "far" && parts != "far,near")
        return file_error("hairis:parts must be \"far\", \"far,near\", " + huang_parts_list() + " (got \"" + parts +
                          "\")");
    const long long far_rows = (long long)theta_r_count * t.theta_i_count;
    NearFieldData near;
    if (parts == "far,near") {
        if (Status s = read_near_header(spec, far_rows, near)) return *s;
    }
    const long long expected_width = std::max<long long>(t.phi_count, near.theta_i_cells ? near.theta_i_cells + 1 : 0);
    const long long expected_height = far_rows + near.rows();
    if (spec.width != expected_width || spec.height != expected_height || spec.depth != 1 || spec.x != 0 || spec.y != 0)
        return file_error("image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                          " but the metadata needs " + std::to_string(expected_width) + "x" +
                          std::to_string(expected_height));

    const OIIO::ParamValue *nodes = spec.find_attribute("hairis:theta_r_nodes");
    if (!nodes || nodes->type().basetype != TypeDesc::FLOAT || nodes->type().basevalues() * size_t(nodes->nvalues()) != size_t(theta_r_count))
        return file_error("hairis:theta_r_nodes must hold " + std::to_string(theta_r_count) + " floats");
    const float *node_values = static_cast<const float *>(nodes->data());
    t.theta_r_nodes.assign(node_values, node_values + theta_r_count);

    Expected<std::vector<int>> n_h = n_h_values_of(spec);
    if (!n_h) return n_h.error();
    t.n_h_values = std::move(n_h).value();

    Expected<std::vector<float>> read = read_pixels(*in);
    in->close();
    if (!read) return read.error();
    const size_t width = size_t(spec.width);
    if (Status s = read_far_part(read.value(), width, far_rows, t)) return *s;
    if (near.theta_i_cells) {
        if (Status s = read_near_part(read.value(), width, far_rows, near)) return *s;
        t.near_field = std::make_shared<const NearFieldData>(std::move(near));
    }
    if (Status s = t.validate()) return *s;
    return t;
}

Expected<TableSet> read_table_file(const std::string &path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) return file_error("cannot open \"" + path + "\" for reading");
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (file.bad()) return file_error("cannot read \"" + path + "\"");
    Expected<TableSet> t = decode_table_exr(bytes.data(), bytes.size());
    if (!t) return Error{t.error().message + " (in \"" + path + "\")"};
    return t;
}

Status write_table_file(const TableSet &tables, const std::string &path) {
    Expected<std::vector<unsigned char>> bytes = encode_table_exr(tables);
    if (!bytes) return bytes.error();
    const std::string temp = path + ".tmp-hairis";
    {
        std::ofstream file(temp, std::ios::binary | std::ios::trunc);
        if (!file) return file_error("cannot write \"" + temp + "\" (is the folder writable?)");
        file.write(reinterpret_cast<const char *>(bytes.value().data()), std::streamsize(bytes.value().size()));
        file.close();
        if (!file) {
            std::remove(temp.c_str());
            return file_error("writing \"" + temp + "\" failed (disk full?)");
        }
    }
    if (std::rename(temp.c_str(), path.c_str()) != 0) {
        std::remove(temp.c_str());
        return file_error("cannot rename \"" + temp + "\" to \"" + path + "\"");
    }
    return std::nullopt;
}

}  // namespace hairis
