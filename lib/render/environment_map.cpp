#include "render/environment_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace hairis {

namespace {

constexpr float kPiF = float(kPi);
constexpr float kTwoPiF = float(kTwoPi);

// A direction is refused as a Mapping target beyond this condition number (‖A‖·‖A⁻¹‖,
// Frobenius): the map would squeeze the image into a sliver of the sphere.
constexpr double kMaxConditionNumber = 1e6;

using Mat3d = double[3][3];

std::string describe(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", v);
    return text;
}

// ∫_{−∞}^{t} of the tent max(0, 1 − |x|).
double tent_cdf(double t) {
    if (t <= -1.0) return 0.0;
    if (t <= 0.0) return 0.5 * (1.0 + t) * (1.0 + t);
    if (t < 1.0) return 1.0 - 0.5 * (1.0 - t) * (1.0 - t);
    return 1.0;
}

// The integrals of the tents of texels i (centre i + ½, period `texels`) over each of `cells`
// equal intervals of [0, texels]: the linear interpolant's integral over cell k is
// Σ value_i · weight over taps(k).
struct Taps {
    std::vector<int> begin;  // cells + 1 offsets into texel / weight
    std::vector<int> texel;
    std::vector<double> weight;
};

Taps tent_taps(int cells, int texels) {
    Taps taps;
    taps.begin.push_back(0);
    for (int k = 0; k < cells; ++k) {
        const double a0 = double(k) * texels / cells, a1 = double(k + 1) * texels / cells;
        // Centres within (a0 − 1, a1 + 1) overlap the cell.
        for (long long i = (long long)std::floor(a0 - 1.5); i <= (long long)std::ceil(a1 + 0.5);
             ++i) {
            const double c = double(i) + 0.5;
            const double w = tent_cdf(a1 - c) - tent_cdf(a0 - c);
            if (!(w > 0.0)) continue;
            const long long m = ((i % texels) + texels) % texels;
            taps.texel.push_back(int(m));
            taps.weight.push_back(w);
        }
        taps.begin.push_back(int(taps.texel.size()));
    }
    return taps;
}

bool invert3(const Mat3d a, Mat3d inv, double &det) {
    const double c00 = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    const double c01 = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    const double c02 = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    det = a[0][0] * c00 + a[0][1] * c01 + a[0][2] * c02;
    if (!(std::isfinite(det) && det != 0.0)) return false;
    const double r = 1.0 / det;
    inv[0][0] = c00 * r;
    inv[1][0] = c01 * r;
    inv[2][0] = c02 * r;
    inv[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) * r;
    inv[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) * r;
    inv[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) * r;
    inv[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) * r;
    inv[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) * r;
    inv[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) * r;
    return true;
}

double frobenius(const Mat3d a) {
    double s = 0;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) s += a[i][k] * a[i][k];
    return std::sqrt(s);
}

Vec3 apply(const float m[3][3], Vec3 v) {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Cycles' u of a unit texture-space direction (direction_to_equirectangular).
float texture_u(Vec3 t) { return (std::atan2(t.y, t.x) - kPiF) / (-kTwoPiF); }

// A positive double as a positive float: tiny weights keep the smallest float, not zero.
float positive_float(double x) {
    const float f = float(x);
    return x > 0.0 && !(f > 0.0f) ? std::numeric_limits<float>::denorm_min() : f;
}

Status check_vec(const char *name, Vec3 v) {
    const std::string n(name);
    return first_error(check::finite((n + ".x").c_str(), v.x), check::finite((n + ".y").c_str(), v.y),
                       check::finite((n + ".z").c_str(), v.z));
}

}  // namespace

Mat4 euler_xyz_rotation(Vec3 r) {
    const double cx = std::cos(double(r.x)), cy = std::cos(double(r.y)), cz = std::cos(double(r.z));
    const double sx = std::sin(double(r.x)), sy = std::sin(double(r.y)), sz = std::sin(double(r.z));
    const double m[3][3] = {{cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz},
                            {cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz},
                            {-sy, cy * sx, cy * cx}};
    Mat4 out;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) out.m[i][k] = float(m[i][k]);
    return out;
}

Expected<Mat4> mapping_node_transform(const MappingNode &node) {
    if (Status s = first_error(check_vec("mapping location", node.location),
                               check_vec("mapping rotation", node.rotation),
                               check_vec("mapping scale", node.scale)))
        return *s;
    const float s[3] = {node.scale.x, node.scale.y, node.scale.z};
    for (int k = 0; k < 3; ++k)
        if (s[k] == 0.0f)
            return Error{std::string("mapping scale.") + "xyz"[k] +
                         " must not be 0: the map of directions would be singular"};
    const bool uses_location = node.type == MappingType::Point || node.type == MappingType::Texture;
    if (uses_location &&
        (node.location.x != 0.0f || node.location.y != 0.0f || node.location.z != 0.0f))
        return Error{"mapping location must be (0, 0, 0) for the Point and Texture types (got (" +
                     describe(node.location.x) + ", " + describe(node.location.y) + ", " +
                     describe(node.location.z) +
                     ")): a translated direction is not a rotation of the sphere"};
    const Mat4 r = euler_xyz_rotation(node.rotation);
    Mat4 a;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
            switch (node.type) {
                case MappingType::Point:
                case MappingType::Vector: a.m[i][k] = r.m[i][k] * s[k]; break;  // R·diag(s)
                case MappingType::Texture: a.m[i][k] = r.m[k][i] / s[i]; break;  // diag(1/s)·Rᵀ
                case MappingType::Normal: a.m[i][k] = r.m[i][k] / s[k]; break;   // R·diag(1/s)
                default: return Error{"mapping type must be Point, Texture, Vector or Normal"};
            }
        }
    return a;
}

namespace {

// The cells' luminance integrals of the bilinear radiance, in texel units (du·dv scaled by w·h),
// computed row by row in parallel; each row relative to its maximum, so that any finite radiance
// fits a float, and its total.
struct CellLuminance {
    std::vector<float> relative;      // W × H, row by row
    std::vector<double> row_integral;  // H
};

Expected<CellLuminance> cell_luminance(const EnvironmentImage &image, Rgb scale, int W, int H) {
    const double sr = double(scale.r), sg = double(scale.g), sb = double(scale.b);
    const int w = image.width(), h = image.height();
    const Taps column_taps = tent_taps(W, w), row_taps = tent_taps(H, h);
    CellLuminance cells;
    cells.relative.resize(size_t(W) * size_t(H));
    cells.row_integral.resize(size_t(H));
    // Scene-linear texels (sRGB images decoded texel by texel: the weights then follow the
    // interpolated decoded texels, a close stand-in for the decoded interpolant Cycles reads,
    // with the same support).
    std::vector<float> decoded;
    if (image.srgb()) {
        decoded = image.rgb();
        for (float &v : decoded) v = srgb_to_linear(v);
    }
    const float *rgb = image.srgb() ? decoded.data() : image.rgb().data();
    double largest = 0;
    for (size_t k = 0; k < image.rgb().size(); k += 3)
        largest = std::max({largest, sr * rgb[k], sg * rgb[k + 1], sb * rgb[k + 2]});
    if (!(largest <= double(std::numeric_limits<float>::max())))
        return Error{"the environment's radiance (image x strength x color) overflows a float: "
                     "its largest value is " + describe(largest)};
    tbb::parallel_for(tbb::blocked_range<int>(0, H), [&](const tbb::blocked_range<int> &range) {
        std::vector<double> lum(static_cast<size_t>(w)), acc(static_cast<size_t>(W));
        for (int J = range.begin(); J != range.end(); ++J) {
            std::fill(acc.begin(), acc.end(), 0.0);
            for (int t = row_taps.begin[size_t(J)]; t < row_taps.begin[size_t(J) + 1]; ++t) {
                const float *row = rgb + size_t(row_taps.texel[size_t(t)]) * size_t(w) * 3;
                const double hy = row_taps.weight[size_t(t)];
                for (int i = 0; i < w; ++i) {
                    const float *p = row + size_t(i) * 3;
                    lum[size_t(i)] = 0.2126 * sr * p[0] + 0.7152 * sg * p[1] + 0.0722 * sb * p[2];
                }
                for (int I = 0; I < W; ++I) {
                    double s = 0;
                    for (int k = column_taps.begin[size_t(I)]; k < column_taps.begin[size_t(I) + 1];
                         ++k)
                        s += column_taps.weight[size_t(k)] * lum[size_t(column_taps.texel[size_t(k)])];
                    acc[size_t(I)] += hy * s;
                }
            }
            double total = 0, peak = 0;
            for (double v : acc) {
                total += v;
                peak = std::max(peak, v);
            }
            cells.row_integral[size_t(J)] = total;
            float *out = cells.relative.data() + size_t(J) * size_t(W);
            for (int I = 0; I < W; ++I)
                out[I] = peak > 0.0 ? positive_float(acc[size_t(I)] / peak) : 0.0f;
        }
    });
    return cells;
}

// The map's resolution: the image's within the automatic bounds, or the one asked for.
Expected<std::pair<int, int>> map_size(const EnvironmentDesc &desc) {
    const EnvironmentImage &image = desc.image;
    int W = desc.map_width, H = desc.map_height;
    if (W == 0 && H == 0) {
        W = std::min(std::max(image.width(), EnvironmentMap::kMinAutoMapWidth),
                     EnvironmentMap::kMaxAutoMapWidth);
        H = std::min(std::max(image.height(), EnvironmentMap::kMinAutoMapHeight),
                     EnvironmentMap::kMaxAutoMapHeight);
    } else {
        if (H == 0) H = std::max(1, W / 2);
        if (Status s = first_error(check::count_in_range("map_width", W, 1, EnvironmentMap::kMaxMapWidth),
                                   check::count_in_range("map_height", H, 1, EnvironmentMap::kMaxMapHeight)))
            return *s;
    }
    return std::make_pair(W, H);
}

}  // namespace

// The mapping: a linear world → texture map, checked to be well conditioned.
Status EnvironmentMap::set_mapping(const Mat4 &m) {
    if (!m.finite()) return Error{"world_to_texture must be finite (it holds nan or inf)"};
    if (m.m[0][3] != 0.0f || m.m[1][3] != 0.0f || m.m[2][3] != 0.0f)
        return Error{"world_to_texture must not translate (column 3 is (" + describe(m.m[0][3]) +
                     ", " + describe(m.m[1][3]) + ", " + describe(m.m[2][3]) +
                     ")): directions are not points"};
    if (m.m[3][0] != 0.0f || m.m[3][1] != 0.0f || m.m[3][2] != 0.0f || m.m[3][3] != 1.0f)
        return Error{"world_to_texture must be affine (last row 0 0 0 1)"};
    Mat3d a, a_inv;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) a[i][k] = double(m.m[i][k]);
    double det = 0;
    if (!invert3(a, a_inv, det))
        return Error{"world_to_texture is singular (determinant " + describe(det) + ")"};
    const double condition = frobenius(a) * frobenius(a_inv);
    if (!(condition <= kMaxConditionNumber))
        return Error{"world_to_texture is nearly singular (condition number " +
                     describe(condition) + " > " + describe(kMaxConditionNumber) + ")"};
    identity_ = true;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
            a_[i][k] = float(a[i][k]);
            a_inv_[i][k] = float(a_inv[i][k]);
            identity_ = identity_ && a[i][k] == (i == k ? 1.0 : 0.0);
        }
    abs_det_ = float(std::fabs(det));
    return std::nullopt;
}

// Uniform columns in u, and rows with edges z_J = −cos(πJ/H) in z.
Status EnvironmentMap::set_grid(int W, int H) {
    Expected<UniformCells> columns = UniformCells::create(0.0f, 1.0f, W);
    if (!columns) return Error{"map_width: " + columns.error().message};
    columns_ = std::move(columns).value();

    // Row edges z_J = −cos(πJ/H), and the largest z a sample of each row takes (never a pole:
    // there the azimuth, and so the cell, would be undefined).
    z_edges_.resize(size_t(H) + 1);
    for (int j = 0; j <= H; ++j) z_edges_[size_t(j)] = float(-std::cos(kPi * j / H));
    z_edges_.front() = -1.0f;
    z_edges_.back() = 1.0f;
    z_last_.resize(size_t(H));
    for (int j = 0; j < H; ++j) {
        const float lo = j == 0 ? -kOneMinusEpsilon : z_edges_[size_t(j)];
        z_last_[size_t(j)] = j + 1 == H ? kOneMinusEpsilon
                                        : std::nextafter(z_edges_[size_t(j) + 1], -2.0f);
        if (!(z_last_[size_t(j)] >= lo))
            return Error{"map_height = " + std::to_string(H) +
                         " leaves a row with no width in z at float precision"};
    }
    return std::nullopt;
}

// The sampling distributions: rows by their luminance × solid angle, columns by luminance.
Status EnvironmentMap::set_distributions(const std::vector<float> &relative,
                                         const std::vector<double> &row_integral, int w, int h) {
    const int W = columns_.count(), H = int(z_edges_.size()) - 1;
    // Row masses: the row's mean luminance × its solid angle (∝ Δz).
    const double cell_texels = (double(w) / W) * (double(h) / H);
    std::vector<double> row_mass(static_cast<size_t>(H));
    double integral = 0;
    for (int J = 0; J < H; ++J) {
        const double dz = double(z_edges_[size_t(J) + 1]) - double(z_edges_[size_t(J)]);
        row_mass[size_t(J)] = row_integral[size_t(J)] * dz;
        integral += row_integral[size_t(J)] / cell_texels * dz * (kTwoPi / W);
    }
    luminance_integral_ = integral;
    black_ = !(integral > 0.0);
    // Nothing to sample: rows by solid angle and uniform columns, the uniform sphere.
    if (black_)
        for (int J = 0; J < H; ++J)
            row_mass[size_t(J)] = double(z_edges_[size_t(J) + 1]) - double(z_edges_[size_t(J)]);

    Expected<DiscreteCdfs> marginal = DiscreteCdfs::create(1, H, [&](int, double *weights) {
        std::copy(row_mass.begin(), row_mass.end(), weights);
    });
    if (!marginal) return Error{"environment map rows: " + marginal.error().message};
    marginal_ = std::move(marginal).value();
    Expected<DiscreteCdfs> conditional = DiscreteCdfs::create(H, W, [&](int J, double *weights) {
        const float *in = relative.data() + size_t(J) * size_t(W);
        for (int I = 0; I < W; ++I) weights[I] = double(in[I]);
    });
    if (!conditional) return Error{"environment map columns: " + conditional.error().message};
    conditional_ = std::move(conditional).value();

    row_factor_.resize(size_t(H));
    for (int J = 0; J < H; ++J) {
        const double dz = double(z_edges_[size_t(J) + 1]) - double(z_edges_[size_t(J)]);
        row_factor_[size_t(J)] = float(double(marginal_.pmf(0, J)) / (dz * (kTwoPi / W)));
    }
    return std::nullopt;
}

Expected<EnvironmentMap> EnvironmentMap::create(EnvironmentDesc desc) {
    const EnvironmentImage &image = desc.image;
    if (image.empty()) return Error{"environment image is empty (0 x 0 pixels)"};
    if (Status s = first_error(check::non_negative("world strength", desc.strength),
                               check::non_negative("world color R", desc.color.r),
                               check::non_negative("world color G", desc.color.g),
                               check::non_negative("world color B", desc.color.b)))
        return *s;
    EnvironmentMap map;
    if (Status s = map.set_mapping(desc.world_to_texture)) return *s;
    Expected<std::pair<int, int>> size = map_size(desc);
    if (!size) return size.error();
    const auto [W, H] = size.value();
    if (Status s = map.set_grid(W, H)) return *s;
    map.scale_ = desc.color * desc.strength;
    Expected<CellLuminance> cells = cell_luminance(image, map.scale_, W, H);
    if (!cells) return cells.error();
    if (Status s = map.set_distributions(cells.value().relative, cells.value().row_integral,
                                         image.width(), image.height()))
        return *s;
    map.image_ = std::move(desc.image);
    return map;
}

int EnvironmentMap::row_of(float z) const {
    const int H = map_height();
    // An estimate from v = 1 − acos(z)/π, corrected against the stored edges that sample()
    // draws between.
    int j = int((1.0f - std::acos(z) * (1.0f / kPiF)) * float(H));
    j = j < 0 ? 0 : (j >= H ? H - 1 : j);
    while (j > 0 && z < z_edges_[size_t(j)]) --j;
    while (j < H - 1 && z >= z_edges_[size_t(j) + 1]) ++j;
    return j;
}

EnvironmentMap::Cell EnvironmentMap::cell_of(Vec3 t) const {
    const float z = std::clamp(t.z, -1.0f, 1.0f);
    return {row_of(z), columns_.cell_of(texture_u(t))};
}

Vec3 EnvironmentMap::to_texture(Vec3 wi, float &length) const {
    const Vec3 t = identity_ ? wi : apply(a_, wi);
    length = std::sqrt(dot(t, t));
    return length > 0.0f ? t / length : Vec3{};
}

float EnvironmentMap::pdf_with_cell(Vec3 wi, Cell &cell) const {
    if (!finite(wi)) return 0.0f;
    if (identity_) {
        // No transform, no Jacobian: the cell of wi itself, normalised only when it is not a
        // unit vector to float precision (sample() hands back its own direction unchanged).
        const float l2 = dot(wi, wi);
        if (!(l2 > 0.0f)) return 0.0f;
        cell = cell_of(std::fabs(l2 - 1.0f) > 1e-5f ? wi / std::sqrt(l2) : wi);
        return cell_pdf(cell);
    }
    float length = 0;
    const Vec3 t = to_texture(wi, length);
    if (!(length > 0.0f)) return 0.0f;
    cell = cell_of(t);
    // |dĉ/dω| = |det A| · (|d| / |A·d|)³.
    const float ratio = std::sqrt(dot(wi, wi)) / length;
    return cell_pdf(cell) * (abs_det_ * ratio * ratio * ratio);
}

float EnvironmentMap::pdf(Vec3 wi) const {
    if (image_.empty()) return 0.0f;
    Cell cell;
    return pdf_with_cell(wi, cell);
}

EnvironmentSample EnvironmentMap::sample(float u0, float u1) const {
    if (image_.empty()) return {};
    const CellChoice r = marginal_.sample(0, u0);
    const CellChoice c = conditional_.sample(r.index, u1);
    const Cell cell{r.index, c.index};
    const int J = cell.row;
    const float z_lo = J == 0 ? -kOneMinusEpsilon : z_edges_[size_t(J)];
    const float dz = z_edges_[size_t(J) + 1] - z_edges_[size_t(J)];
    float tv = r.fraction, tu = c.fraction;
    // A point within float rounding of the cell's border may come back in the neighbouring
    // cell; it is moved inwards (by 1/256, then 1/16 of the cell, then to its centre).
    constexpr float kShrink[3] = {1.0f - 1.0f / 256.0f, 1.0f - 1.0f / 16.0f, 0.0f};
    for (int attempt = 0;; ++attempt) {
        float z = z_edges_[size_t(J)] + tv * dz;
        z = z < z_lo ? z_lo : (z > z_last_[size_t(J)] ? z_last_[size_t(J)] : z);
        const float u = columns_.point_in_cell(cell.column, tu);
        const float phi = kPiF - kTwoPiF * u;
        const float s = std::sqrt((1.0f - z) * (1.0f + z));
        const Vec3 t{s * std::cos(phi), s * std::sin(phi), z};
        const Vec3 wi = identity_ ? t : safe_normalize(apply(a_inv_, t));
        Cell back;
        const float p = pdf_with_cell(wi, back);
        if ((back.row == cell.row && back.column == cell.column) || attempt == 3)
            return {wi, eval(wi), p};
        tv = 0.5f + (r.fraction - 0.5f) * kShrink[attempt];
        tu = 0.5f + (c.fraction - 0.5f) * kShrink[attempt];
    }
}

Rgb EnvironmentMap::texture_radiance(Vec3 t) const {
    // Cycles' direction_to_equirectangular and interp_linear with REPEAT in u and v.
    const int w = image_.width(), h = image_.height();
    const float u = texture_u(t);
    const float v = (std::acos(std::clamp(t.z, -1.0f, 1.0f)) - kPiF) / (-kPiF);
    const float x = u * float(w) - 0.5f, y = v * float(h) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const float tx = x - fx, ty = y - fy;
    auto wrap = [](long long i, int n) { return int(((i % n) + n) % n); };
    const int ix = wrap((long long)fx, w), iy = wrap((long long)fy, h);
    const int nix = ix + 1 == w ? 0 : ix + 1, niy = iy + 1 == h ? 0 : iy + 1;
    const Rgb c = image_.texel(ix, iy) * ((1.0f - ty) * (1.0f - tx)) +
                  image_.texel(nix, iy) * ((1.0f - ty) * tx) +
                  image_.texel(ix, niy) * (ty * (1.0f - tx)) + image_.texel(nix, niy) * (ty * tx);
    return image_.srgb() ? srgb_to_linear(c) : c;
}

Rgb EnvironmentMap::eval(Vec3 wi) const {
    if (image_.empty() || !finite(wi)) return Rgb{};
    float length = 0;
    const Vec3 t = to_texture(wi, length);
    if (!(length > 0.0f)) return Rgb{};
    return scale_ * texture_radiance(t);
}

std::size_t EnvironmentMap::memory_bytes() const {
    return sizeof(*this) + image_.rgb().capacity() * sizeof(float) +
           size_t(DiscreteCdfs::bytes_needed(1, map_height())) +
           size_t(DiscreteCdfs::bytes_needed(map_height(), map_width())) +
           (z_edges_.capacity() + z_last_.capacity() + row_factor_.capacity()) * sizeof(float);
}

}  // namespace hairis
