#include "render/lights.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace hairis {

namespace {

constexpr float kPiF = float(kPi);

bool finite3(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

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

Status check_version(const std::string &name, CyclesVersion v, bool soft_falloff) {
    if (v != CyclesVersion::V3_4 && v != CyclesVersion::V4_5)
        return Error{name + ": cycles must be 3.4 or 4.5 (got " + std::to_string(int(v)) + ")"};
    if (v == CyclesVersion::V3_4 && !soft_falloff)
        return Error{name + ": soft_falloff = 0 (a sphere light) needs cycles = 4.5; Cycles 3.4 "
                            "has only the disk"};
    return std::nullopt;
}

// 1 − cos α for sin²α = s2, without cancellation.
float one_minus_cos_from_sin2(float s2) { return s2 / (1.0f + std::sqrt(std::max(0.0f, 1.0f - s2))); }

// A unit vector at angle acos(cos_theta) from the unit axis, at azimuth 2π·u.
Vec3 cone_direction(Vec3 axis, float cos_theta, float u) {
    Vec3 a, b;
    orthonormal_basis(axis, a, b);
    const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
    const float phi = 2.0f * kPiF * u;
    return safe_normalize(axis * cos_theta + (a * std::cos(phi) + b * std::sin(phi)) * sin_theta);
}

// The inverse of the 3×3 part of m; false when it is singular.
bool invert_linear(const Mat4 &m, float out[3][3]) {
    const double a[3][3] = {{m.m[0][0], m.m[0][1], m.m[0][2]},
                            {m.m[1][0], m.m[1][1], m.m[1][2]},
                            {m.m[2][0], m.m[2][1], m.m[2][2]}};
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(std::isfinite(det) && det != 0.0)) return false;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
            // Cofactor of (k, i) over det.
            const int r0 = (k + 1) % 3, r1 = (k + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
            out[i][k] = float((a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]) / det);
        }
    return true;
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

Rgb area_radiance(Rgb color, float power, float area, CyclesVersion version) {
    const float factor = version == CyclesVersion::V4_5 ? float(kInvPi) : 0.25f;
    return strength(color, power) * (factor / area);
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

Rgb sun_radiance_cycles45(Rgb color, float strength_w_m2, float angle) {
    const float s = std::sin(0.5f * angle);
    return strength(color, strength_w_m2) * (1.0f / (kPiF * s * s));
}

float spot_attenuation(float c, float cos_half, float smooth) {
    if (!(c > cos_half)) return 0.0f;
    const float t = c - cos_half;
    return t < smooth && smooth != 0.0f ? c * smoothstep(t / smooth) : c;
}

float spot_attenuation_cycles45(float z, float cos_half, float smooth) {
    if (!(z > cos_half)) return 0.0f;
    if (smooth == 0.0f) return 1.0f;
    const float f = (z - cos_half) / smooth;
    return f >= 1.0f ? 1.0f : smoothstep(f);
}

}  // namespace cycles_light

Expected<LightSet> LightSet::build(const std::vector<SunLight> &suns,
                                   const std::vector<PointLight> &points,
                                   const std::vector<AreaLight> &areas, const WorldLight &world,
                                   std::vector<EmissiveTriangle> emissive,
                                   std::vector<std::string> *warnings) {
    return build(LightsDesc{suns, points, {}, areas, world}, std::move(emissive), warnings);
}

Expected<LightSet> LightSet::build(const LightsDesc &lights,
                                   std::vector<EmissiveTriangle> emissive,
                                   std::vector<std::string> *warnings) {
    LightSet set;
    if (auto e = set.add_lamps(lights.suns, "sun light")) return *e;
    if (auto e = set.add_lamps(lights.points, "point light")) return *e;
    if (auto e = set.add_lamps(lights.spots, "spot light")) return *e;
    if (auto e = set.add_lamps(lights.areas, "area light", warnings)) return *e;
    if (auto e = set.set_world(lights.world)) return *e;
    set.set_triangles(emissive);
    const bool has_lamps = !set.lamps_.empty(), has_triangles = !set.triangles_.empty();
    set.triangle_pick_ = has_triangles ? (has_lamps ? 0.5f : 1.0f) : 0.0f;
    set.lamp_pick_ = has_lamps ? (1.0f - set.triangle_pick_) / float(set.lamps_.size()) : 0.0f;
    set.by_importance_ = set.lamps_.size() > 1 && set.lamps_.size() <= kMaxImportanceLamps;
    return set;
}

// A point's or a spot's emission: a disk facing the shading point, or a sphere without soft
// falloff, of the light's radius (a point for radius 0).
template <typename Light>
void LightSet::set_point_emission(Lamp &lamp, const Light &p) {
    lamp.radius = p.radius;
    lamp.sphere = !p.soft_falloff && p.radius > 0.0f;
    lamp.invarea = cycles_light::point_invarea(p.radius);
    lamp.value = p.radius > 0.0f ? cycles_light::point_radiance(p.color, p.power, p.radius)
                                 : cycles_light::point_intensity(p.color, p.power);
    lamp.importance = luminance(cycles_light::point_intensity(p.color, p.power));
}

// Adds the lamp of each light (none for one that emits nothing), naming light i "<kind> i" in
// its errors.
template <typename Light, typename... Extra>
Status LightSet::add_lamps(const std::vector<Light> &lights, const char *kind, Extra... extra) {
    for (std::size_t i = 0; i < lights.size(); ++i) {
        std::optional<Lamp> lamp;
        const std::string name = std::string(kind) + " " + std::to_string(i);
        if (auto e = lamp_of(lights[i], name, lamp, extra...)) return *e;
        if (lamp) lamps_.push_back(*lamp);
    }
    return std::nullopt;
}

// A sun's lamp, checked; none for a black one.
Status LightSet::lamp_of(const SunLight &s, const std::string &name, std::optional<Lamp> &out) {
    if (auto e = check_position(name + ": to_sun", s.to_sun)) return *e;
    if (!(length(s.to_sun) > 0.0f))
        return Error{name + ": to_sun must not be the zero vector"};
    if (auto e = check_color(name + ":", s.color)) return *e;
    if (auto e = check::non_negative((name + ": strength").c_str(), s.strength)) return *e;
    if (!(s.angle >= 0.0f && s.angle < kPiF))
        return Error{name + ": angle must be in [0, pi) radians (got " +
                     std::to_string(s.angle) + ")"};
    if (auto e = check_version(name, s.cycles, true)) return *e;
    if (s.strength == 0.0f || s.color.is_black()) return std::nullopt;
    Lamp lamp;
    lamp.type = LampType::Sun;
    lamp.cycles = s.cycles;
    lamp.value = cycles_light::strength(s.color, s.strength);
    lamp.direction = safe_normalize(s.to_sun);
    lamp.importance = luminance(cycles_light::strength(s.color, s.strength));
    lamp.radius = std::tan(0.5f * s.angle);
    lamp.cos_half = std::cos(0.5f * s.angle);
    lamp.invarea = cycles_light::sun_invarea(s.angle);
    if (s.cycles == CyclesVersion::V4_5) {
        lamp.radius = 0.5f * s.angle;
        const float h = std::sin(0.25f * s.angle);
        lamp.one_minus_cos_half = 2.0f * h * h;
        if (s.angle > 0.0f) lamp.value = cycles_light::sun_radiance_cycles45(s.color, s.strength, s.angle);
    }
    out = lamp;
    return std::nullopt;
}

// A point light's lamp, checked; none for a black one.
Status LightSet::lamp_of(const PointLight &p, const std::string &name, std::optional<Lamp> &out) {
    if (auto e = check_position(name + ": position", p.position)) return *e;
    if (auto e = check_color(name + ":", p.color)) return *e;
    if (auto e = check::non_negative((name + ": power").c_str(), p.power)) return *e;
    if (auto e = check::non_negative((name + ": radius").c_str(), p.radius)) return *e;
    if (auto e = check_version(name, p.cycles, p.soft_falloff)) return *e;
    if (p.power == 0.0f || p.color.is_black()) return std::nullopt;
    Lamp lamp;
    lamp.type = LampType::Point;
    lamp.cycles = p.cycles;
    lamp.position = p.position;
    set_point_emission(lamp, p);
    out = lamp;
    return std::nullopt;
}

// A spot's lamp, checked; none for a black one.
Status LightSet::lamp_of(const SpotLight &p, const std::string &name, std::optional<Lamp> &out) {
    if (!p.light_to_world.finite())
        return Error{name + ": light_to_world must be finite (it holds NaN or infinity)"};
    const Vec3 z = p.light_to_world.column(2);
    if (!(length(z) > 0.0f))
        return Error{name + ": light_to_world has a zero Z axis (no direction to shine in)"};
    if (auto e = check_color(name + ":", p.color)) return *e;
    if (auto e = check::non_negative((name + ": power").c_str(), p.power)) return *e;
    if (auto e = check::non_negative((name + ": radius").c_str(), p.radius)) return *e;
    if (!(p.spot_size > 0.0f && p.spot_size <= kPiF))
        return Error{name + ": spot_size must be in (0, pi] radians (got " +
                     std::to_string(p.spot_size) + ")"};
    if (!(p.spot_blend >= 0.0f && p.spot_blend <= 1.0f))
        return Error{name + ": spot_blend must be in [0, 1] (got " +
                     std::to_string(p.spot_blend) + ")"};
    if (auto e = check_version(name, p.cycles, p.soft_falloff)) return *e;
    Lamp lamp;
    lamp.type = LampType::Spot;
    lamp.cycles = p.cycles;
    if (p.cycles == CyclesVersion::V4_5 && !invert_linear(p.light_to_world, lamp.world_to_light))
        return Error{name + ": light_to_world is singular (Cycles 4.5 shapes the cone in the "
                            "light's own frame)"};
    if (p.power == 0.0f || p.color.is_black()) return std::nullopt;
    lamp.position = p.light_to_world.column(3);
    lamp.direction = safe_normalize(-z);
    set_point_emission(lamp, p);
    lamp.cos_half = std::cos(0.5f * p.spot_size);
    lamp.smooth = (1.0f - lamp.cos_half) * p.spot_blend;
    out = lamp;
    return std::nullopt;
}

// An area light's lamp, checked; none for a black or empty one (an empty one with a warning).
Status LightSet::lamp_of(const AreaLight &a, const std::string &name, std::optional<Lamp> &out,
                         std::vector<std::string> *warnings) {
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
    if (auto e = check_version(name, a.cycles, true)) return *e;
    const Vec3 z = a.light_to_world.column(2);
    if (!(length(z) > 0.0f))
        return Error{name + ": light_to_world has a zero Z axis (no emitting direction)"};
    if (a.power == 0.0f || a.color.is_black()) return std::nullopt;
    const float area = cycles_light::area_light_area(a);
    if (!(area > 0.0f) || !std::isfinite(area)) {
        if (warnings)
            warnings->push_back(name + ": zero size, left out (it would emit nothing)");
        return std::nullopt;
    }
    const bool two_sizes = a.shape == AreaShape::Rectangle || a.shape == AreaShape::Ellipse;
    Lamp lamp;
    lamp.type = LampType::Area;
    lamp.cycles = a.cycles;
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
    lamp.value = cycles_light::area_radiance(a.color, a.power, area, a.cycles);
    lamp.importance = luminance(lamp.value) * area;  // its intensity along the normal
    out = lamp;
    return std::nullopt;
}

// The world: a constant colour, or an environment that is a lamp unless it is not sampled.
Status LightSet::set_world(const WorldLight &world) {
    if (auto e = check_color("world:", world.color)) return *e;
    if (auto e = check::non_negative("world: strength", world.strength)) return *e;
    // A constant world is not light-sampled (as in Cycles 3.4): BSDF sampling alone finds it,
    // and sampling it uniformly would take a share of the light samples from the lamps that
    // need them, which adds variance at one bounce.
    if (world.environment) {
        // An environment is a lamp (Cycles' background light) unless its Sampling is None or
        // it is black: then BSDF sampling alone finds it.
        environment_ = world.environment;
        environment_sampled_ = world.light_sampled && !world.environment->black();
        if (environment_sampled_) {
            Lamp lamp;
            lamp.type = LampType::Environment;
            lamp.importance = float(world.environment->luminance_integral() / 4.0);  // πL̄
            lamps_.push_back(lamp);
        }
    } else {
        world_ = world.color * world.strength;
    }
    return std::nullopt;
}

// Emissive triangles, picked by area; degenerate and black ones left out.
void LightSet::set_triangles(const std::vector<EmissiveTriangle> &emissive) {
    triangle_cdf_.push_back(0.0f);
    double total = 0;
    for (const EmissiveTriangle &t : emissive) {
        const float area = 0.5f * length(cross(t.p1 - t.p0, t.p2 - t.p0));
        if (!(area > 0.0f) || t.radiance.is_black()) continue;
        triangles_.push_back(t);
        total += area;
        triangle_cdf_.push_back(float(total));
    }
    if (!triangles_.empty()) {
        for (float &c : triangle_cdf_) c = float(c / total);
        triangle_cdf_.back() = 1.0f;
        triangle_area_ = float(total);
    } else {
        triangle_cdf_.clear();
    }
}

// The lamps' selection probabilities seen from p; the lamps' importance total is computed when
// a lamp first asks (most rays cross no lamp).
class LightSet::LampPicks {
  public:
    LampPicks(const LightSet &set, Vec3 p) : set_(set), p_(p) {}
    float operator()(const Lamp &lamp) const {
        if (set_.by_importance_ && total_ < 0.0f) total_ = set_.importance_total(p_);
        return set_.lamp_pick(lamp, p_, total_);
    }

  private:
    const LightSet &set_;
    Vec3 p_;
    mutable float total_ = -1.0f;
};

std::optional<LightSample> LightSet::sample(Vec3 p, float u_select, float u0, float u1) const {
    if (empty()) return std::nullopt;
    float u = u_select;
    if (!triangles_.empty()) {
        if (lamps_.empty()) return sample_triangle(p, u, u0, u1);
        if (u < 0.5f) return sample_triangle(p, 2.0f * u, u0, u1);
        u = 2.0f * (u - 0.5f);
    }
    const int n = int(lamps_.size());
    if (!by_importance_) {
        const int i = std::min(int(u * float(n)), n - 1);
        return sample_lamp(lamps_[std::size_t(i)], p, u0, u1, lamp_pick_);
    }
    // The importances once (summed in importance_total's order, so the pick is the density's).
    float importance[kMaxImportanceLamps];
    float total = 0.0f;
    for (int i = 0; i < n; ++i) total += importance[i] = importance_at(lamps_[std::size_t(i)], p);
    float cumulative = 0.0f;
    for (int i = 0; i < n; ++i) {
        const float share = share_of(importance[i], total);
        cumulative += share;
        if (u < cumulative || i == n - 1)
            return sample_lamp(lamps_[std::size_t(i)], p, u0, u1, (1.0f - triangle_pick_) * share);
    }
    return std::nullopt;
}

float LightSet::importance_at(const Lamp &lamp, Vec3 p) {
    switch (lamp.type) {
        case LampType::Point: {
            const Vec3 d = p - lamp.position;
            return lamp.importance / std::max({dot(d, d), lamp.radius * lamp.radius, 1e-12f});
        }
        case LampType::Spot: {
            const Vec3 d = p - lamp.position;
            const float d2 = dot(d, d), r2 = lamp.radius * lamp.radius;
            return lamp.importance * spot_reach(lamp, d, d2) / std::max({d2, r2, 1e-12f});
        }
        case LampType::Area: {
            const Vec3 d = p - lamp.position;
            const float d2 = dot(d, d), area = 1.0f / lamp.invarea;
            if (d2 <= area) return lamp.importance / area;  // close: much of it faces p
            return lamp.importance * std::max(0.0f, dot(d, lamp.direction)) / (d2 * std::sqrt(d2));
        }
        case LampType::Sun:
        case LampType::Environment: return lamp.importance;
    }
    return 0.0f;
}

float LightSet::importance_total(Vec3 p) const {
    float total = 0.0f;
    for (const Lamp &lamp : lamps_) total += importance_at(lamp, p);
    return total;
}

float LightSet::share_of(float importance, float total) const {
    const float uniform = 1.0f / float(lamps_.size());
    if (!(total > 0.0f) || !std::isfinite(total)) return uniform;
    return kUniformShare * uniform + (1.0f - kUniformShare) * importance / total;
}

float LightSet::lamp_pick(const Lamp &lamp, Vec3 p, float total) const {
    return by_importance_ ? (1.0f - triangle_pick_) * share_of(importance_at(lamp, p), total) : lamp_pick_;
}

float LightSet::lamp_selection_probability(Vec3 p, std::size_t i) const {
    return i < lamps_.size() ? LampPicks(*this, p)(lamps_[i]) : 0.0f;
}

std::optional<LightSample> LightSet::sample_lamp(const Lamp &lamp, Vec3 p, float u0,
                                                 float u1, float pick) const {
    LightSample s;
    switch (lamp.type) {
        case LampType::Point:
        case LampType::Spot: return sample_point_like(lamp, p, u0, u1, pick);
        case LampType::Environment: {
            const EnvironmentSample e = environment_->sample(u0, u1);
            if (!(e.pdf > 0.0f) || e.radiance.is_black()) return std::nullopt;
            s.wi = e.wi;
            s.distance = INFINITY;
            s.value = e.radiance;
            s.pdf = pick * e.pdf;
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
                s.pdf = pick / rect.solid_angle();
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
            s.pdf = pick * lamp.invarea * t * t / cos_light;
            return s;
        }
        case LampType::Sun: {
            s.distance = INFINITY;
            if (lamp.radius == 0.0f) {
                s.wi = lamp.direction;
                s.value = lamp.value;
                s.pdf = pick;
                s.delta = true;
                return s;
            }
            if (lamp.cycles == CyclesVersion::V4_5) {
                // Uniform in the cone: cos θ uniform in [cos(a/2), 1].
                s.wi = cone_direction(lamp.direction, 1.0f - u0 * lamp.one_minus_cos_half, u1);
                if (!(dot(s.wi, lamp.direction) >= lamp.cos_half)) return std::nullopt;
                s.value = lamp.value;
                s.pdf = pick / (2.0f * kPiF * lamp.one_minus_cos_half);
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
            s.pdf = pick * pdf;
            return s;
        }
    }
    return std::nullopt;
}

float LightSet::spot_factor(const Lamp &lamp, Vec3 n) {
    if (lamp.type != LampType::Spot) return 1.0f;
    const float c = spot_axis_cosine(lamp, n);
    if (lamp.cycles == CyclesVersion::V3_4) return cycles_light::spot_attenuation(c, lamp.cos_half, lamp.smooth);
    return cycles_light::spot_attenuation_cycles45(c, lamp.cos_half, lamp.smooth);
}

float LightSet::spot_reach(const Lamp &lamp, Vec3 d, float d2) {
    const float r2 = lamp.radius * lamp.radius;
    if (!(d2 > r2)) return 1.0f;  // within the light's radius: any direction may reach p
    // The axis angle of p, less the disk's angular radius seen from p (the light may leave
    // from any point of it), against the cone's half angle.
    const float c = spot_axis_cosine(lamp, d * (1.0f / std::sqrt(d2)));
    const float angle = std::acos(std::clamp(c, -1.0f, 1.0f)) - std::asin(std::sqrt(r2 / d2));
    return angle <= std::acos(std::clamp(lamp.cos_half, -1.0f, 1.0f)) ? 1.0f : 0.0f;
}

float LightSet::spot_axis_cosine(const Lamp &lamp, Vec3 n) {
    if (lamp.cycles == CyclesVersion::V3_4) return dot(lamp.direction, n);
    const float(&m)[3][3] = lamp.world_to_light;
    const Vec3 local = safe_normalize(Vec3{m[0][0] * n.x + m[0][1] * n.y + m[0][2] * n.z,
                                           m[1][0] * n.x + m[1][1] * n.y + m[1][2] * n.z,
                                           m[2][0] * n.x + m[2][1] * n.y + m[2][2] * n.z});
    return -local.z;
}

float LightSet::sphere_pdf(float d2, float r2) {
    if (d2 > r2) return 1.0f / (2.0f * kPiF * one_minus_cos_from_sin2(r2 / d2));
    return 0.25f / kPiF;  // from inside: the uniform sphere of directions
}

Rgb LightSet::point_like_value(const Lamp &lamp, Vec3 p, Vec3 wi) const {
    if (lamp.type != LampType::Spot) return lamp.value;
    // A sphere spot does not attenuate the light of a point inside it.
    if (lamp.sphere) {
        const Vec3 d = p - lamp.position;
        if (!(dot(d, d) > lamp.radius * lamp.radius)) return lamp.value;
    }
    return lamp.value * spot_factor(lamp, -wi);
}

std::optional<LightSample> LightSet::sample_point_like(const Lamp &lamp, Vec3 p, float u0,
                                                       float u1, float pick) const {
    LightSample s;
    const Vec3 to_p = p - lamp.position;
    const float d2 = dot(to_p, to_p);
    if (!(d2 > 0.0f)) return std::nullopt;
    if (lamp.radius == 0.0f) {
        s.distance = std::sqrt(d2);
        s.wi = -to_p / s.distance;
        s.value = point_like_value(lamp, p, s.wi) / d2;
        if (s.value.is_black()) return std::nullopt;
        s.pdf = pick;
        s.delta = true;
        return s;
    }
    const float d = std::sqrt(d2);
    const Vec3 n = to_p / d;  // from the light towards p
    if (lamp.sphere) {
        const float r2 = lamp.radius * lamp.radius;
        float cos_theta;  // between wi and the direction to the centre
        if (d2 > r2) {
            cos_theta = 1.0f - u0 * one_minus_cos_from_sin2(r2 / d2);
            s.wi = cone_direction(-n, cos_theta, u1);
        } else {
            const float z = 1.0f - 2.0f * u0;
            s.wi = cone_direction(-n, z, u1);
            cos_theta = z;
        }
        // Law of cosines: the near intersection from outside, the far one from inside.
        const float disc = std::sqrt(std::max(0.0f, r2 - d2 + d2 * cos_theta * cos_theta));
        s.distance = d2 > r2 ? d * cos_theta - disc : d * cos_theta + disc;
        if (!(s.distance > 0.0f)) return std::nullopt;
        s.value = point_like_value(lamp, p, s.wi);
        if (s.value.is_black()) return std::nullopt;
        s.pdf = pick * sphere_pdf(d2, r2);
        return s;
    }
    Vec3 a, b;
    orthonormal_basis(n, a, b);
    float x, y;
    concentric_disk(u0, u1, x, y);
    const Vec3 q = lamp.position + (a * x + b * y) * lamp.radius;
    const Vec3 w = q - p;
    const float t = length(w);
    if (!(t > 0.0f)) return std::nullopt;
    s.wi = w / t;
    const float cos_light = -dot(n, s.wi);
    if (!(cos_light > 0.0f)) return std::nullopt;
    s.distance = t;
    s.value = point_like_value(lamp, p, s.wi);
    if (s.value.is_black()) return std::nullopt;
    s.pdf = pick * lamp.invarea * t * t / cos_light;
    return s;
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

template <typename Visit>
void LightSet::visit_lamps_along_ray(Vec3 origin, Vec3 dir, float tmin, float tmax, Vec3 from,
                                     Visit &&visit) const {
    const LampPicks picks(*this, from);
    for (const Lamp &lamp : lamps_) {
        if (lamp.type == LampType::Point || lamp.type == LampType::Spot) {
            if (lamp.radius == 0.0f) continue;
            const Vec3 to_origin = origin - lamp.position;
            if (lamp.sphere) {
                // Every direction from inside sees the sphere, also for spots (Cycles 4.5's
                // spot_light_intersect ignores rays leaving the centre there, while its light
                // samples cover them: hairis keeps the two consistent).
                const float d2 = dot(to_origin, to_origin), r2 = lamp.radius * lamp.radius;
                const float b = -dot(to_origin, dir);  // distance along dir to the closest point
                const Vec3 closest = to_origin + dir * b;
                const float h2 = dot(closest, closest);
                if ((d2 > r2 && b < 0.0f) || h2 > r2) continue;
                const float half_chord = std::sqrt(r2 - h2);
                const float t = d2 > r2 ? b - half_chord : b + half_chord;
                if (!(t > tmin && t < tmax)) continue;
                const Rgb value = point_like_value(lamp, origin, dir);
                if (!value.is_black()) visit(value, picks(lamp) * sphere_pdf(d2, r2));
                continue;
            }
            const Vec3 n = safe_normalize(to_origin);
            const float denom = dot(dir, n);
            if (!(denom < 0.0f)) continue;
            const float t = dot(lamp.position - origin, n) / denom;
            if (!(t > tmin && t < tmax)) continue;
            const Vec3 q = origin + dir * t - lamp.position;
            if (dot(q, q) > lamp.radius * lamp.radius) continue;
            const Rgb value = point_like_value(lamp, origin, dir);
            if (!value.is_black()) visit(value, picks(lamp) * lamp.invarea * t * t / -denom);
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
            float light_pdf;
            if (lamp.solid_angle) {
                const SphericalRectangle rect(origin,
                                              lamp.position - (lamp.axis_u + lamp.axis_v) * 0.5f,
                                              lamp.axis_u, lamp.axis_v);
                light_pdf = rect.solid_angle() > 0.0f ? picks(lamp) / rect.solid_angle() : 0.0f;
            } else {
                light_pdf = picks(lamp) * lamp.invarea * t * t / -denom;
            }
            visit(lamp.value, light_pdf);
        }
    }
}

template <typename Visit>
void LightSet::visit_escaped(Vec3 origin, Vec3 dir, Visit &&visit) const {
    const LampPicks picks(*this, origin);
    for (const Lamp &lamp : lamps_) {
        if (lamp.type != LampType::Sun || lamp.radius == 0.0f) continue;
        if (lamp.cycles == CyclesVersion::V4_5) {
            if (!(dot(dir, lamp.direction) >= lamp.cos_half)) continue;
            visit(lamp.value, picks(lamp) / (2.0f * kPiF * lamp.one_minus_cos_half));
            continue;
        }
        const float c = dot(dir, lamp.direction);
        if (!(c >= lamp.cos_half) || !(c > 0.0f)) continue;
        const float pdf = lamp.invarea / (c * c * c);
        visit(lamp.value * pdf, picks(lamp) * pdf);
    }
}

Rgb LightSet::lamps_along_ray(Vec3 origin, Vec3 dir, float tmin, float tmax, float bsdf_pdf,
                              bool use_mis, std::optional<Vec3> from) const {
    Rgb sum;
    visit_lamps_along_ray(origin, dir, tmin, tmax, from.value_or(origin), [&](Rgb value, float light_pdf) {
        sum += value * (use_mis ? power_heuristic(bsdf_pdf, light_pdf) : 1.0f);
    });
    return sum;
}

Rgb LightSet::escaped(Vec3 origin, Vec3 dir, float bsdf_pdf, bool use_mis, bool include_world) const {
    Rgb sum;
    visit_escaped(origin, dir, [&](Rgb value, float light_pdf) {
        sum += value * (use_mis ? power_heuristic(bsdf_pdf, light_pdf) : 1.0f);
    });
    if (!include_world) return sum;
    if (!environment_) return sum + world_;  // a constant world is never light-sampled
    const Rgb radiance = environment_->eval(dir);
    if (radiance.is_black()) return sum;
    const float w = use_mis && environment_sampled_
                        ? power_heuristic(bsdf_pdf, world_pdf(origin, dir))
                        : 1.0f;
    return sum + radiance * w;
}

float LightSet::world_pdf(Vec3 p, Vec3 dir) const {
    if (!environment_sampled_) return 0.0f;
    const Lamp &lamp = lamps_.back();  // the environment is the last lamp
    return LampPicks(*this, p)(lamp) * environment_->pdf(dir);
}

float LightSet::pdf(Vec3 p, Vec3 wi) const {
    float total = 0.0f;
    auto add = [&](Rgb, float light_pdf) { total += light_pdf; };
    visit_lamps_along_ray(p, wi, 0.0f, INFINITY, p, add);
    visit_escaped(p, wi, add);
    total += world_pdf(p, wi);
    // Emissive triangles that the ray crosses (Möller and Trumbore).
    for (const EmissiveTriangle &tri : triangles_) {
        const Vec3 e1 = tri.p1 - tri.p0, e2 = tri.p2 - tri.p0;
        const Vec3 h = cross(wi, e2);
        const float det = dot(e1, h);
        if (det == 0.0f) continue;
        const Vec3 o = p - tri.p0;
        const float u = dot(o, h) / det;
        const Vec3 q = cross(o, e1);
        const float v = dot(wi, q) / det;
        const float t = dot(e2, q) / det;
        if (!(u >= 0.0f && v >= 0.0f && u + v <= 1.0f && t > 0.0f)) continue;
        const float abs_cos = std::fabs(dot(safe_normalize(cross(e1, e2)), wi));
        total += emissive_triangle_pdf(t, abs_cos);
    }
    return total;
}

std::size_t LightSet::memory_bytes() const {
    return sizeof(*this) + lamps_.capacity() * sizeof(Lamp) +
           triangles_.capacity() * sizeof(EmissiveTriangle) +
           triangle_cdf_.capacity() * sizeof(float) +
           (environment_ ? environment_->memory_bytes() : 0);
}

}  // namespace hairis
