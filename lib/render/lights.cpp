#include "render/lights.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace hairis {

namespace {

constexpr float kPiF = float(kPi);

bool finite3(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

bool is_black(Rgb c) { return c.r == 0.0f && c.g == 0.0f && c.b == 0.0f; }

Status check_color(const std::string &name, Rgb c) {
    for (int i = 0; i < 3; ++i)
        if (auto e = check::non_negative((name + " colour").c_str(), c[i])) return e;
    return std::nullopt;
}

Status check_position(const std::string &name, Vec3 p) {
    if (finite3(p)) return std::nullopt;
    return Error{name + " must be finite (got (" + std::to_string(p.x) + ", " +
                 std::to_string(p.y) + ", " + std::to_string(p.z) + "))"};
}

}  // namespace

void concentric_disk(float u0, float u1, float &x, float &y) {
    const float a = 2.0f * u0 - 1.0f, b = 2.0f * u1 - 1.0f;
    if (a == 0.0f && b == 0.0f) {
        x = y = 0.0f;
        return;
    }
    float r, phi;
    if (std::fabs(a) > std::fabs(b)) {
        r = a;
        phi = (kPiF / 4.0f) * (b / a);
    } else {
        r = b;
        phi = (kPiF / 2.0f) - (kPiF / 4.0f) * (a / b);
    }
    x = r * std::cos(phi);
    y = r * std::sin(phi);
}

void orthonormal_basis(Vec3 n, Vec3 &a, Vec3 &b) {
    // Duff et al. 2017, "Building an Orthonormal Basis, Revisited".
    const float sign = std::copysign(1.0f, n.z);
    const float p = -1.0f / (sign + n.z);
    const float q = n.x * n.y * p;
    a = {1.0f + sign * n.x * n.x * p, sign * q, -sign * n.x};
    b = {q, sign + n.y * n.y * p, -n.y};
}

SphericalRectangle::SphericalRectangle(Vec3 p, Vec3 corner, Vec3 ex, Vec3 ey) : o_(p) {
    const float lx = length(ex), ly = length(ey);
    if (!(lx > 0.0f) || !(ly > 0.0f)) return;
    x_ = ex / lx;
    y_ = ey / ly;
    z_ = cross(x_, y_);
    const Vec3 d = corner - p;
    x0_ = dot(d, x_);
    y0_ = dot(d, y_);
    z0_ = dot(d, z_);
    if (z0_ > 0.0f) {  // look at the rectangle from its negative side
        z0_ = -z0_;
        z_ = -z_;
    }
    if (!(z0_ < 0.0f)) return;
    x1_ = x0_ + lx;
    y1_ = y0_ + ly;
    // The corners seen from p, and the normals of the four planes through p and an edge.
    const Vec3 v00{x0_, y0_, z0_}, v01{x0_, y1_, z0_}, v10{x1_, y0_, z0_}, v11{x1_, y1_, z0_};
    const Vec3 n0 = safe_normalize(cross(v00, v10)), n1 = safe_normalize(cross(v10, v11)),
               n2 = safe_normalize(cross(v11, v01)), n3 = safe_normalize(cross(v01, v00));
    auto angle = [](Vec3 a, Vec3 b) { return std::acos(std::clamp(-dot(a, b), -1.0f, 1.0f)); };
    const float g0 = angle(n0, n1), g1 = angle(n1, n2), g2 = angle(n2, n3), g3 = angle(n3, n0);
    b0_ = n0.z;
    b1_ = n2.z;
    k_ = 2.0f * kPiF - g2 - g3;
    const float s = g0 + g1 - k_;
    solid_angle_ = std::isfinite(s) && s > 0.0f ? s : 0.0f;
}

Vec3 SphericalRectangle::sample(float u, float v) const {
    // The x of the sample: invert the solid angle of the sub-rectangle [x0, xu].
    const float au = u * solid_angle_ + k_;
    const float fu = (std::cos(au) * b0_ - b1_) / std::sin(au);
    float cu = std::copysign(1.0f, fu) / std::sqrt(fu * fu + b0_ * b0_);
    cu = std::clamp(cu, -1.0f, 1.0f);
    float xu = -(cu * z0_) / std::sqrt(std::max(1e-12f, 1.0f - cu * cu));
    xu = std::clamp(xu, x0_, x1_);
    // Then y, uniform in the projected height along that column.
    const float dist = std::sqrt(xu * xu + z0_ * z0_);
    const float h0 = y0_ / std::sqrt(dist * dist + y0_ * y0_);
    const float h1 = y1_ / std::sqrt(dist * dist + y1_ * y1_);
    const float hv = h0 + v * (h1 - h0), hv2 = hv * hv;
    const float yv = hv2 < 1.0f - 1e-6f ? (hv * dist) / std::sqrt(1.0f - hv2) : y1_;
    return o_ + x_ * xu + y_ * std::clamp(yv, y0_, y1_) + z_ * z0_;
}

namespace cycles_light {

float point_invarea(float radius) {
    return radius > 0.0f ? 1.0f / (kPiF * radius * radius) : 1.0f;
}

Rgb point_radiance(Rgb color, float power, float radius) {
    return strength(color, power) * (point_invarea(radius) * (0.25f / kPiF));
}

Rgb point_intensity(Rgb color, float power) { return strength(color, power) * (0.25f / kPiF); }

float area_light_area(const AreaLight &light) {
    const bool two_sizes =
        light.shape == AreaShape::Rectangle || light.shape == AreaShape::Ellipse;
    const float size_v = two_sizes ? light.size_y : light.size_x;
    const float len_u = length(light.light_to_world.column(0)) * light.size_x;
    const float len_v = length(light.light_to_world.column(1)) * size_v;
    float area = len_u * len_v;
    if (light.shape == AreaShape::Disk || light.shape == AreaShape::Ellipse)
        area *= kPiF / 4.0f;
    return area;
}

Rgb area_radiance(Rgb color, float power, float area) {
    return strength(color, power) * (0.25f / area);
}

float sun_invarea(float angle) {
    const float radius = std::tan(0.5f * angle);
    const float area = kPiF * radius * radius;
    return area > 0.0f ? 1.0f / area : 1.0f;
}

Rgb sun_radiance(Rgb color, float strength_w_m2, float angle, float cos_theta) {
    return strength(color, strength_w_m2) *
           (sun_invarea(angle) / (cos_theta * cos_theta * cos_theta));
}

}  // namespace cycles_light

Expected<LightSet> LightSet::build(const std::vector<SunLight> &suns,
                                   const std::vector<PointLight> &points,
                                   const std::vector<AreaLight> &areas, const WorldLight &world,
                                   std::vector<EmissiveTriangle> emissive,
                                   std::vector<std::string> *warnings) {
    LightSet set;

    for (std::size_t i = 0; i < suns.size(); ++i) {
        const SunLight &s = suns[i];
        const std::string name = "sun light " + std::to_string(i);
        if (auto e = check_position(name + ": to_sun", s.to_sun)) return *e;
        if (!(length(s.to_sun) > 0.0f))
            return Error{name + ": to_sun must not be the zero vector"};
        if (auto e = check_color(name + ":", s.color)) return *e;
        if (auto e = check::non_negative((name + ": strength").c_str(), s.strength)) return *e;
        if (!(s.angle >= 0.0f && s.angle < kPiF))
            return Error{name + ": angle must be in [0, pi) radians (got " +
                         std::to_string(s.angle) + ")"};
        if (s.strength == 0.0f || is_black(s.color)) continue;
        Lamp lamp;
        lamp.type = LampType::Sun;
        lamp.value = cycles_light::strength(s.color, s.strength);
        lamp.direction = safe_normalize(s.to_sun);
        lamp.radius = std::tan(0.5f * s.angle);
        lamp.cos_half = std::cos(0.5f * s.angle);
        lamp.invarea = cycles_light::sun_invarea(s.angle);
        set.lamps_.push_back(lamp);
    }

    for (std::size_t i = 0; i < points.size(); ++i) {
        const PointLight &p = points[i];
        const std::string name = "point light " + std::to_string(i);
        if (auto e = check_position(name + ": position", p.position)) return *e;
        if (auto e = check_color(name + ":", p.color)) return *e;
        if (auto e = check::non_negative((name + ": power").c_str(), p.power)) return *e;
        if (auto e = check::non_negative((name + ": radius").c_str(), p.radius)) return *e;
        if (p.power == 0.0f || is_black(p.color)) continue;
        Lamp lamp;
        lamp.type = LampType::Point;
        lamp.position = p.position;
        lamp.radius = p.radius;
        lamp.invarea = cycles_light::point_invarea(p.radius);
        lamp.value = p.radius > 0.0f ? cycles_light::point_radiance(p.color, p.power, p.radius)
                                     : cycles_light::point_intensity(p.color, p.power);
        set.lamps_.push_back(lamp);
    }

    for (std::size_t i = 0; i < areas.size(); ++i) {
        const AreaLight &a = areas[i];
        const std::string name = "area light " + std::to_string(i);
        if (!a.light_to_world.finite())
            return Error{name + ": light_to_world must be finite (it holds NaN or infinity)"};
        const int shape = int(a.shape);
        if (shape < 0 || shape > 3)
            return Error{name + ": shape must be Square (0), Rectangle (1), Disk (2) or Ellipse "
                                "(3) (got " + std::to_string(shape) + ")"};
        if (auto e = check::non_negative((name + ": size_x").c_str(), a.size_x)) return *e;
        if (auto e = check::non_negative((name + ": size_y").c_str(), a.size_y)) return *e;
        if (auto e = check_color(name + ":", a.color)) return *e;
        if (auto e = check::non_negative((name + ": power").c_str(), a.power)) return *e;
        const Vec3 z = a.light_to_world.column(2);
        if (!(length(z) > 0.0f))
            return Error{name + ": light_to_world has a zero Z axis (no emitting direction)"};
        if (a.power == 0.0f || is_black(a.color)) continue;
        const float area = cycles_light::area_light_area(a);
        if (!(area > 0.0f) || !std::isfinite(area)) {
            if (warnings)
                warnings->push_back(name + ": zero size, left out (it would emit nothing)");
            continue;
        }
        const bool two_sizes = a.shape == AreaShape::Rectangle || a.shape == AreaShape::Ellipse;
        Lamp lamp;
        lamp.type = LampType::Area;
        lamp.position = a.light_to_world.column(3);
        lamp.axis_u = a.light_to_world.column(0) * a.size_x;
        lamp.axis_v = a.light_to_world.column(1) * (two_sizes ? a.size_y : a.size_x);
        lamp.direction = safe_normalize(-z);
        lamp.round = a.shape == AreaShape::Disk || a.shape == AreaShape::Ellipse;
        // Solid-angle sampling needs a true rectangle (no shear in the object matrix).
        lamp.solid_angle =
            !lamp.round && std::fabs(dot(lamp.axis_u, lamp.axis_v)) <=
                               1e-5f * length(lamp.axis_u) * length(lamp.axis_v);
        lamp.invarea = 1.0f / area;
        lamp.value = cycles_light::area_radiance(a.color, a.power, area);
        set.lamps_.push_back(lamp);
    }

    if (auto e = check_color("world:", world.color)) return *e;
    if (auto e = check::non_negative("world: strength", world.strength)) return *e;
    // A constant world is not light-sampled (as in Cycles 3.4): BSDF sampling alone finds it,
    // and sampling it uniformly would take a share of the light samples from the lamps that
    // need them (measured: ~16% more variance at one bounce in the Cycles-comparison scene).
    set.world_ = world.color * world.strength;

    // Emissive triangles, by area.
    set.triangle_cdf_.push_back(0.0f);
    double total = 0;
    for (const EmissiveTriangle &t : emissive) {
        const float area = 0.5f * length(cross(t.p1 - t.p0, t.p2 - t.p0));
        if (!(area > 0.0f) || is_black(t.radiance)) continue;
        set.triangles_.push_back(t);
        total += area;
        set.triangle_cdf_.push_back(float(total));
    }
    if (!set.triangles_.empty()) {
        for (float &c : set.triangle_cdf_) c = float(c / total);
        set.triangle_cdf_.back() = 1.0f;
        set.triangle_area_ = float(total);
    } else {
        set.triangle_cdf_.clear();
    }

    const bool has_lamps = !set.lamps_.empty(), has_triangles = !set.triangles_.empty();
    set.triangle_pick_ = has_triangles ? (has_lamps ? 0.5f : 1.0f) : 0.0f;
    set.lamp_pick_ = has_lamps ? (1.0f - set.triangle_pick_) / float(set.lamps_.size()) : 0.0f;
    return set;
}

std::optional<LightSample> LightSet::sample(Vec3 p, float u_select, float u0, float u1) const {
    if (empty()) return std::nullopt;
    float u = u_select;
    if (!triangles_.empty()) {
        if (lamps_.empty()) return sample_triangle(p, u, u0, u1);
        if (u < 0.5f) return sample_triangle(p, 2.0f * u, u0, u1);
        u = 2.0f * (u - 0.5f);
    }
    const int n = int(lamps_.size());
    const int i = std::min(int(u * float(n)), n - 1);
    return sample_lamp(lamps_[std::size_t(i)], p, u0, u1);
}

std::optional<LightSample> LightSet::sample_lamp(const Lamp &lamp, Vec3 p, float u0,
                                                 float u1) const {
    LightSample s;
    switch (lamp.type) {
        case LampType::Point: {
            if (lamp.radius == 0.0f) {
                const Vec3 d = lamp.position - p;
                const float t2 = dot(d, d);
                if (!(t2 > 0.0f)) return std::nullopt;
                s.distance = std::sqrt(t2);
                s.wi = d / s.distance;
                s.value = lamp.value / t2;
                s.pdf = lamp_pick_;
                s.delta = true;
                return s;
            }
            const Vec3 n = safe_normalize(p - lamp.position);
            if (dot(n, n) == 0.0f) return std::nullopt;
            Vec3 a, b;
            orthonormal_basis(n, a, b);
            float x, y;
            concentric_disk(u0, u1, x, y);
            const Vec3 q = lamp.position + (a * x + b * y) * lamp.radius;
            const Vec3 d = q - p;
            const float t = length(d);
            if (!(t > 0.0f)) return std::nullopt;
            s.wi = d / t;
            const float cos_light = -dot(n, s.wi);
            if (!(cos_light > 0.0f)) return std::nullopt;
            s.distance = t;
            s.value = lamp.value;
            s.pdf = lamp_pick_ * lamp.invarea * t * t / cos_light;
            return s;
        }
        case LampType::Area: {
            if (!(dot(p - lamp.position, lamp.direction) > 0.0f)) return std::nullopt;
            if (lamp.solid_angle) {
                const SphericalRectangle rect(
                    p, lamp.position - (lamp.axis_u + lamp.axis_v) * 0.5f, lamp.axis_u,
                    lamp.axis_v);
                if (!(rect.solid_angle() > 0.0f)) return std::nullopt;
                const Vec3 d = rect.sample(u0, u1) - p;
                const float t = length(d);
                if (!(t > 0.0f)) return std::nullopt;
                s.wi = d / t;
                if (!(-dot(lamp.direction, s.wi) > 0.0f)) return std::nullopt;
                s.distance = t;
                s.value = lamp.value;
                s.pdf = lamp_pick_ / rect.solid_angle();
                return s;
            }
            Vec3 q;
            if (lamp.round) {
                float x, y;
                concentric_disk(u0, u1, x, y);
                q = lamp.position + lamp.axis_u * (0.5f * x) + lamp.axis_v * (0.5f * y);
            } else {
                q = lamp.position + lamp.axis_u * (u0 - 0.5f) + lamp.axis_v * (u1 - 0.5f);
            }
            const Vec3 d = q - p;
            const float t = length(d);
            if (!(t > 0.0f)) return std::nullopt;
            s.wi = d / t;
            const float cos_light = -dot(lamp.direction, s.wi);
            if (!(cos_light > 0.0f)) return std::nullopt;
            s.distance = t;
            s.value = lamp.value;
            s.pdf = lamp_pick_ * lamp.invarea * t * t / cos_light;
            return s;
        }
        case LampType::Sun: {
            s.distance = INFINITY;
            if (lamp.radius == 0.0f) {
                s.wi = lamp.direction;
                s.value = lamp.value;
                s.pdf = lamp_pick_;
                s.delta = true;
                return s;
            }
            Vec3 a, b;
            orthonormal_basis(lamp.direction, a, b);
            float x, y;
            concentric_disk(u0, u1, x, y);
            s.wi = safe_normalize(lamp.direction + (a * x + b * y) * lamp.radius);
            const float c = dot(lamp.direction, s.wi);
            if (!(c > 0.0f)) return std::nullopt;
            const float pdf = lamp.invarea / (c * c * c);
            s.value = lamp.value * pdf;
            s.pdf = lamp_pick_ * pdf;
            return s;
        }
    }
    return std::nullopt;
}

std::optional<LightSample> LightSet::sample_triangle(Vec3 p, float u_select, float u0,
                                                     float u1) const {
    // The triangle whose CDF interval holds u_select.
    const auto it = std::upper_bound(triangle_cdf_.begin(), triangle_cdf_.end(), u_select);
    const std::size_t i = std::min<std::size_t>(
        std::size_t(std::max<std::ptrdiff_t>(it - triangle_cdf_.begin() - 1, 0)),
        triangles_.size() - 1);
    const EmissiveTriangle &tri = triangles_[i];
    // Uniform point: the square-root parametrisation.
    const float su = std::sqrt(u0);
    const float b0 = 1.0f - su, b1 = u1 * su;
    const Vec3 q = tri.p0 * b0 + tri.p1 * b1 + tri.p2 * (1.0f - b0 - b1);
    const Vec3 d = q - p;
    const float t = length(d);
    if (!(t > 0.0f)) return std::nullopt;
    LightSample s;
    s.wi = d / t;
    const Vec3 n = safe_normalize(cross(tri.p1 - tri.p0, tri.p2 - tri.p0));
    const float abs_cos = std::fabs(dot(n, s.wi));
    if (!(abs_cos > 0.0f)) return std::nullopt;
    s.distance = t;
    s.value = tri.radiance;
    s.pdf = emissive_triangle_pdf(t, abs_cos);
    s.skip_geometry = tri.geometry;
    s.skip_primitive = tri.primitive;
    return s;
}

float LightSet::emissive_triangle_pdf(float t, float abs_cos) const {
    if (triangles_.empty() || !(abs_cos > 0.0f)) return 0.0f;
    return triangle_pick_ / triangle_area_ * t * t / abs_cos;
}

Rgb LightSet::lamps_along_ray(Vec3 origin, Vec3 dir, float tmin, float tmax, float bsdf_pdf,
                              bool use_mis) const {
    Rgb sum;
    for (const Lamp &lamp : lamps_) {
        if (lamp.type == LampType::Point) {
            if (lamp.radius == 0.0f) continue;
            const Vec3 n = safe_normalize(origin - lamp.position);
            const float denom = dot(dir, n);
            if (!(denom < 0.0f)) continue;
            const float t = dot(lamp.position - origin, n) / denom;
            if (!(t > tmin && t < tmax)) continue;
            const Vec3 q = origin + dir * t - lamp.position;
            if (dot(q, q) > lamp.radius * lamp.radius) continue;
            const float w =
                use_mis ? power_heuristic(bsdf_pdf, lamp_pick_ * lamp.invarea * t * t / -denom)
                        : 1.0f;
            sum += lamp.value * w;
        } else if (lamp.type == LampType::Area) {
            const float denom = dot(dir, lamp.direction);
            if (!(denom < 0.0f)) continue;  // one-sided
            const float t = dot(lamp.position - origin, lamp.direction) / denom;
            if (!(t > tmin && t < tmax)) continue;
            const Vec3 q = origin + dir * t - lamp.position;
            const float s = dot(q, lamp.axis_u) / dot(lamp.axis_u, lamp.axis_u);
            const float v = dot(q, lamp.axis_v) / dot(lamp.axis_v, lamp.axis_v);
            const bool inside = lamp.round ? (4.0f * (s * s + v * v) <= 1.0f)
                                           : (std::fabs(s) <= 0.5f && std::fabs(v) <= 0.5f);
            if (!inside) continue;
            float w = 1.0f;
            if (use_mis) {
                float light_pdf;
                if (lamp.solid_angle) {
                    const SphericalRectangle rect(
                        origin, lamp.position - (lamp.axis_u + lamp.axis_v) * 0.5f, lamp.axis_u,
                        lamp.axis_v);
                    light_pdf = rect.solid_angle() > 0.0f ? lamp_pick_ / rect.solid_angle() : 0.0f;
                } else {
                    light_pdf = lamp_pick_ * lamp.invarea * t * t / -denom;
                }
                w = power_heuristic(bsdf_pdf, light_pdf);
            }
            sum += lamp.value * w;
        }
    }
    return sum;
}

Rgb LightSet::escaped(Vec3 dir, float bsdf_pdf, bool use_mis, bool include_world) const {
    Rgb sum;
    for (const Lamp &lamp : lamps_) {
        if (lamp.type == LampType::Sun) {
            if (lamp.radius == 0.0f) continue;
            const float c = dot(dir, lamp.direction);
            if (!(c >= lamp.cos_half) || !(c > 0.0f)) continue;
            const float pdf = lamp.invarea / (c * c * c);
            const float w = use_mis ? power_heuristic(bsdf_pdf, lamp_pick_ * pdf) : 1.0f;
            sum += lamp.value * (pdf * w);
        }
    }
    if (include_world) sum += world_;  // never light-sampled: full weight
    return sum;
}

std::size_t LightSet::memory_bytes() const {
    return sizeof(*this) + lamps_.capacity() * sizeof(Lamp) +
           triangles_.capacity() * sizeof(EmissiveTriangle) +
           triangle_cdf_.capacity() * sizeof(float);
}

}  // namespace hairis
