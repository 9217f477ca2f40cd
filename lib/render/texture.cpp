#include "render/texture.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

namespace hairis {

namespace {

// Texel coordinates beyond this are folded (Repeat, Mirror) or clamped (Extend, Clip) in
// 64-bit integers without overflow.
constexpr double kFar = 1e15;

long long wrap_periodic(long long i, long long n) {
    long long m = i % n;
    return m < 0 ? m + n : m;
}

long long wrap_mirror(long long i, long long n) {
    const long long m = std::llabs(i + (i < 0 ? 1 : 0)) % (2 * n);
    return m >= n ? 2 * n - m - 1 : m;
}

// The integer part (floor) and the fraction of t.
void split(double t, long long &i, float &fraction) {
    t = std::clamp(t, -kFar, kFar);
    const double f = std::floor(t);
    i = (long long)f;
    fraction = float(t - f);
}

}  // namespace

Expected<ImageTexture> ImageTexture::create(ImageTextureDesc desc) {
    if (!desc.image || desc.image->empty()) return Error{"image texture: the image is empty"};
    ImageTexture texture;
    if (desc.use_mapping) {
        if (desc.mapping.type == MappingType::Normal)
            return Error{"image texture: a Mapping of type Normal is not supported on UV "
                         "coordinates (it normalizes the vector); use Point, Texture or Vector"};
        MappingNode linear = desc.mapping;
        linear.location = {0, 0, 0};
        Expected<Mat4> a = mapping_node_transform(linear);
        if (!a) return Error{"image texture: " + a.error().message};
        const Vec3 t = desc.mapping.location;
        if (!(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z)))
            return Error{"image texture: mapping location must be finite"};
        Mat4 m = a.value();
        Vec3 offset{0, 0, 0};
        if (desc.mapping.type == MappingType::Point) offset = t;
        if (desc.mapping.type == MappingType::Texture) offset = -m.transform_vector(t);
        m.m[0][3] = offset.x;
        m.m[1][3] = offset.y;
        m.m[2][3] = offset.z;
        texture.uv_to_texture_ = m;
    }
    texture.desc_ = std::move(desc);
    return texture;
}

Rgb ImageTexture::lookup(float u, float v) const {
    if (!desc_.use_mapping) return lookup_mapped(u, v);
    const Vec3 p = uv_to_texture_.transform_point({u, v, 0.0f});
    return lookup_mapped(p.x, p.y);
}

Rgb ImageTexture::lookup_mapped(float x, float y) const {
    const EnvironmentImage &image = *desc_.image;
    if (!std::isfinite(x) || !std::isfinite(y)) return {};
    const long long w = image.width(), h = image.height();
    const TextureExtension ext = desc_.extension;
    auto fold = [&](long long i, long long n) -> long long {
        switch (ext) {
            case TextureExtension::Repeat: return wrap_periodic(i, n);
            case TextureExtension::Mirror: return wrap_mirror(i, n);
            case TextureExtension::Extend: return std::clamp(i, 0ll, n - 1);
            case TextureExtension::Clip: return i;
        }
        return i;
    };
    auto texel = [&](long long i, long long j) -> Rgb {
        if (ext == TextureExtension::Clip && (i < 0 || i >= w || j < 0 || j >= h)) return {};
        return image.texel(int(i), int(j));
    };
    Rgb c;
    if (desc_.interpolation == TextureInterpolation::Closest) {
        long long i, j;
        float unused;
        split(double(x) * double(w), i, unused);
        split(double(y) * double(h), j, unused);
        c = texel(fold(i, w), fold(j, h));
    } else {
        long long i, j;
        float tx, ty;
        split(double(x) * double(w) - 0.5, i, tx);
        split(double(y) * double(h) - 0.5, j, ty);
        if (ext == TextureExtension::Clip && (i < -1 || i >= w || j < -1 || j >= h)) return {};
        const long long i0 = fold(i, w), j0 = fold(j, h);
        // Repeat and Mirror fold the neighbour from the folded index, as Cycles does.
        const long long i1 = ext == TextureExtension::Repeat ? wrap_periodic(i0 + 1, w) : fold(i + 1, w);
        const long long j1 = ext == TextureExtension::Repeat ? wrap_periodic(j0 + 1, h) : fold(j + 1, h);
        c = texel(i0, j0) * ((1.0f - ty) * (1.0f - tx)) + texel(i1, j0) * ((1.0f - ty) * tx) +
            texel(i0, j1) * (ty * (1.0f - tx)) + texel(i1, j1) * (ty * tx);
    }
    return image.srgb() ? srgb_to_linear(c) : c;
}

}  // namespace hairis
