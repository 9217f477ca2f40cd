#include "render/scene.h"

#include <embree3/rtcore.h>


#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <string>
#include <sys/types.h>
#include <vector>

namespace hairis {

namespace {

LightsDesc lights_of(const SceneDesc &desc) {
    return {desc.suns, desc.point_lights, desc.spot_lights, desc.area_lights, desc.world};
}

struct alignas(16) Float4 {
    float x, y, z, w;
};

struct CurveGeometry {
    std::vector<Float4> cvs;              // n + 2 control points per curve (ends duplicated)
    std::vector<Vec3> normals;            // empty, or the normal of each control point
    std::vector<std::uint32_t> segments;  // first control point of each segment
    std::vector<std::uint32_t> curve_of;  // the curve of each segment
    std::uint32_t material = 0;
    std::vector<CurveInput> inputs;       // of the kept curves and their points only
    std::size_t set = 0;                  // its index in SceneDesc::curves
};

struct MeshGeometry {
    std::vector<float> vertices;            // xyz per vertex, plus one float of padding
    std::vector<std::uint32_t> indices;     // 3 per kept triangle
    std::vector<std::uint32_t> materials;   // 1 per kept triangle
    std::vector<std::uint8_t> emissive;     // 1 per kept triangle: in the light set
    std::vector<Vec3> normals;              // 3 per kept triangle, or none
    std::vector<float> uvs;                 // 6 per kept triangle, or none
    std::size_t mesh = 0;                   // its index in SceneDesc::meshes
    unsigned geometry_id = 0;               // Embree's
};

struct GeometryInfo {
    bool is_curve = false;
    std::uint32_t index = 0;  // into curves or meshes
};

// The context handed to Embree: the primitives a ray must ignore, whether the inside of a
// curve tube counts (CurveBackfaces::Hit) and, for rays that let hair through, where the hair
// hits go.
struct TraceContext {
    RTCIntersectContext rtc;
    PrimRef skip_a, skip_b;
    bool hit_curve_backfaces = false;
    std::vector<StrandCrossing> *strands = nullptr;
    // With strands: once it holds this many records, curve hits are accepted (the ray's tfar
    // shrinks to them) instead of let through, which ends the traversal early.
    std::size_t accept_after = std::numeric_limits<std::size_t>::max();
};

bool skipped(const TraceContext *ctx, unsigned geom, unsigned prim) {
    return (geom == ctx->skip_a.geometry && prim == ctx->skip_a.primitive) ||
           (geom == ctx->skip_b.geometry && prim == ctx->skip_b.primitive);
}

// Triangles: ignore the primitives the ray starts or ends on.
void triangle_filter(const RTCFilterFunctionNArguments *args) {
    const auto *ctx = reinterpret_cast<const TraceContext *>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        if (skipped(ctx, RTCHitN_geomID(args->hit, args->N, i),
                    RTCHitN_primID(args->hit, args->N, i)))
            args->valid[i] = 0;
    }
}

// What a curve geometry does with hits on the inside of a tube: as the context says (Catmull-Rom
// tubes), never hit (linear curves, as Cycles 5.0 renders them), or none (flat ribbons).
enum class InsideHits { AsContext, Culled, NoInside };

// Curves: ignore hits on any segment of the curve the ray starts on (the geometry's user data
// maps segments to curves) and the culled hits on the inside of the tube (the backface culling
// of Cycles with Embree 3).
template <InsideHits kInside>
void curve_filter(const RTCFilterFunctionNArguments *args) {
    const auto *ctx = reinterpret_cast<const TraceContext *>(args->context);
    const auto *curve_of = static_cast<const std::uint32_t *>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const float d = RTCRayN_dir_x(args->ray, args->N, i) * RTCHitN_Ng_x(args->hit, args->N, i) +
                        RTCRayN_dir_y(args->ray, args->N, i) * RTCHitN_Ng_y(args->hit, args->N, i) +
                        RTCRayN_dir_z(args->ray, args->N, i) * RTCHitN_Ng_z(args->hit, args->N, i);
        const bool culled = kInside != InsideHits::NoInside && d > 0.0f &&
                            (kInside == InsideHits::Culled || !ctx->hit_curve_backfaces);
        if (culled || skipped(ctx, RTCHitN_geomID(args->hit, args->N, i),
                              curve_of[RTCHitN_primID(args->hit, args->N, i)])) {
            args->valid[i] = 0;
        } else if (ctx->strands) {
            // Let hair through: record the hit (its distance is the ray's tfar) and reject it.
            // Embree may report one hit of a round curve many times over (hundreds for a
            // straight one); the repeats are recorded once.
            StrandCrossing c;
            c.t = RTCRayN_tfar(args->ray, args->N, i);
            c.segment = {RTCHitN_geomID(args->hit, args->N, i), RTCHitN_primID(args->hit, args->N, i)};
            c.u = RTCHitN_u(args->hit, args->N, i);
            std::vector<StrandCrossing> &out = *ctx->strands;
            bool repeat = false;
            for (std::size_t k = out.size(); k-- > 0 && out.size() - k <= 8;)
                if (out[k].segment.geometry == c.segment.geometry &&
                    out[k].segment.primitive == c.segment.primitive && out[k].t == c.t) {
                    repeat = true;
                    break;
                }
            if (!repeat) out.push_back(c);
            if (out.size() < ctx->accept_after) args->valid[i] = 0;
        }
    }
}

bool finite3(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool is_hair(const Material &m) { return std::holds_alternative<HairMaterial>(m); }

std::string describe(Vec3 v) {
    return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) +
           ")";
}

// Embree's uniform Catmull-Rom basis on the segment p1..p2 and its derivative.
void catmull_rom(const Float4 &p0, const Float4 &p1, const Float4 &p2, const Float4 &p3, float t,
                 Float4 &value, Float4 &derivative) {
    const float t2 = t * t, t3 = t2 * t;
    const float b0 = 0.5f * (-t3 + 2.0f * t2 - t);
    const float b1 = 0.5f * (3.0f * t3 - 5.0f * t2 + 2.0f);
    const float b2 = 0.5f * (-3.0f * t3 + 4.0f * t2 + t);
    const float b3 = 0.5f * (t3 - t2);
    const float d0 = 0.5f * (-3.0f * t2 + 4.0f * t - 1.0f);
    const float d1 = 0.5f * (9.0f * t2 - 10.0f * t);
    const float d2 = 0.5f * (-9.0f * t2 + 8.0f * t + 1.0f);
    const float d3 = 0.5f * (3.0f * t2 - 2.0f * t);
    value = {b0 * p0.x + b1 * p1.x + b2 * p2.x + b3 * p3.x,
             b0 * p0.y + b1 * p1.y + b2 * p2.y + b3 * p3.y,
             b0 * p0.z + b1 * p1.z + b2 * p2.z + b3 * p3.z,
             b0 * p0.w + b1 * p1.w + b2 * p2.w + b3 * p3.w};
    derivative = {d0 * p0.x + d1 * p1.x + d2 * p2.x + d3 * p3.x,
                  d0 * p0.y + d1 * p1.y + d2 * p2.y + d3 * p3.y,
                  d0 * p0.z + d1 * p1.z + d2 * p2.z + d3 * p3.z,
                  d0 * p0.w + d1 * p1.w + d2 * p2.w + d3 * p3.w};
}

// The floats per curve or point of a curve input.
int components_of(const CurveInput &in) {
    return in.closure_weight >= 0 ? 1 : hair_input_info(in.input).components;
}

// Whether some closure of a hair material reads `input` per strand.
bool any_closure_reads(const HairMaterial &hair, HairInput input) {
    const int count = hair.mixture ? hair.mixture->size() : 1;
    for (int k = 0; k < count; ++k) {
        const ShadingModel *model = hair.mixture ? hair.mixture->closure(k).model() : hair.shading.model();
        const StrandInputReader *strands = model ? model->strand_inputs() : nullptr;
        if (strands && strands->reads_input(input)) return true;
    }
    return false;
}

// The straight segment p1..p2 (Cycles' linear_basis_eval) and its derivative.
void linear(const Float4 &p1, const Float4 &p2, float t, Float4 &value, Float4 &derivative) {
    derivative = {p2.x - p1.x, p2.y - p1.y, p2.z - p1.z, p2.w - p1.w};
    value = {p1.x + t * derivative.x, p1.y + t * derivative.y, p1.z + t * derivative.z,
             p1.w + t * derivative.w};
}

// Whether a curve set's inputs fit its material: each known once, closure weights on a
// mixture with that closure, node inputs on a material that varies per strand and reads them
// (some closure does, for a mixture).
Status check_inputs_fit(const std::vector<CurveInput> &inputs, const std::string &set, std::uint32_t index,
                        const Material &material) {
    const auto *hair = std::get_if<HairMaterial>(&material);
    const int closures = hair && hair->mixture ? hair->mixture->size() : 0;
    const ShadingModel *model = hair ? hair->shading.model() : nullptr;
    const StrandInputReader *strands = model ? model->strand_inputs() : nullptr;
    std::uint32_t seen_weights = 0, seen = 0;
    for (const CurveInput &in : inputs) {
        if (in.closure_weight >= 0) {
            const std::string name = set + ", closure " + std::to_string(in.closure_weight) + "'s weight";
            if (in.closure_weight >= closures)
                return Error{name + ": the material has " + std::to_string(closures) +
                             " mixed hair closure(s); a weight per strand needs a closure of a hair mixture"};
            if ((seen_weights >> unsigned(in.closure_weight)) & 1u) return Error{name + ": given twice"};
            seen_weights |= 1u << unsigned(in.closure_weight);
            continue;
        }
        if (!strands)
            return Error{set + ": has curve inputs, but its material " + std::to_string(index) +
                         " does not vary per strand (it needs a hair material made for curve inputs, e.g. "
                         "ChiangStrands or HuangStrands)"};
        if (int(in.input) >= kHairInputCount)
            return Error{set + ": a curve input is not a node input (" + std::to_string(int(in.input)) + ")"};
        const std::string name = set + ", input " + hair_input_info(in.input).name;
        if ((seen >> unsigned(in.input)) & 1u) return Error{name + ": given twice"};
        seen |= 1u << unsigned(in.input);
        if (!any_closure_reads(*hair, in.input))
            return Error{name + ": the material's parametrization does not read it"};
    }
    return std::nullopt;
}

// A curve set's inputs: fit for its material, sized for its curves or points, in range.
Status check_curve_inputs(const HairCurves &hc, const std::string &set, const Material &material) {
    if (auto e = check_inputs_fit(hc.inputs, set, hc.material, material)) return e;
    const std::size_t curves = hc.first.size() - 1, points = hc.points.size();
    for (const CurveInput &in : hc.inputs) {
        const bool weight = in.closure_weight >= 0;
        const std::string name = weight ? set + ", closure " + std::to_string(in.closure_weight) + "'s weight"
                                        : set + ", input " + hair_input_info(in.input).name;
        const std::size_t k = std::size_t(components_of(in)), n = in.per_point ? points : curves;
        if (in.values.size() != n * k)
            return Error{name + ": has " + std::to_string(in.values.size()) + " values; " + std::to_string(n) +
                         (in.per_point ? " points" : " curves") + (weight ? "" : " of " + std::to_string(k)) +
                         " need " + std::to_string(n * k)};
        for (std::size_t i = 0; i < n; ++i) {
            const std::string where = set + (in.per_point ? ", point " : ", curve ") + std::to_string(i) + ": ";
            if (weight) {
                if (!std::isfinite(in.values[i]) || in.values[i] < 0.0f)
                    return Error{name + (in.per_point ? ", point " : ", curve ") + std::to_string(i) + ": " +
                                 std::to_string(in.values[i]) + " (weights must be finite and >= 0)"};
            } else if (Status bad = check_hair_input(in.input, in.values.data() + i * k, where)) {
                return bad;
            }
        }
    }
    return std::nullopt;
}

// Each material's own values: hair materials have a fiber, diffuse ones an albedo in [0, 1]
// and a non-negative emission.
Status check_materials(const std::vector<Material> &materials) {
    for (std::size_t m = 0; m < materials.size(); ++m) {
        if (const auto *hair = std::get_if<HairMaterial>(&materials[m])) {
            if (!hair->shading.model())
                return Error{"material " + std::to_string(m) + ": hair material has no fiber"};
        } else if (const auto *d = std::get_if<DiffuseMaterial>(&materials[m])) {
            const std::string name = "material " + std::to_string(m);
            for (int i = 0; i < 3; ++i) {
                if (auto e = check::in_range((name + ": albedo").c_str(), d->albedo[i], 0.0, 1.0)) return *e;
                if (auto e = check::non_negative((name + ": emission").c_str(), d->emission[i])) return *e;
            }
        }
    }
    return std::nullopt;
}

// A material index of `what`: in range, and a surface material where `surface`.
Status check_material_index(const std::vector<Material> &materials, const std::string &what, std::uint32_t m,
                            bool surface) {
    if (m >= materials.size())
        return Error{what + ": material index " + std::to_string(m) + " is out of range (the scene has " +
                     std::to_string(materials.size()) + " materials)"};
    if (surface && is_hair(materials[m]))
        return Error{what + ": material " + std::to_string(m) + " is a hair material; meshes need a surface material"};
    return std::nullopt;
}

// A curve set's arrays: a hair material, one radius (and at most one normal) per point, the
// curves' first points, and its per-strand inputs.
Status check_curve_set(const HairCurves &hc, const std::string &set, const std::vector<Material> &materials) {
    if (auto e = check_material_index(materials, set, hc.material, false)) return *e;
    if (hc.radii.size() != hc.points.size())
        return Error{set + ": radii has " + std::to_string(hc.radii.size()) +
                     " entries but points has " + std::to_string(hc.points.size()) +
                     " (one radius per point)"};
    if (hc.first.empty() || hc.first.front() != 0 || hc.first.back() != hc.points.size())
        return Error{set + ": first must start at 0 and end at the point count (" +
                     std::to_string(hc.points.size()) + ") with one entry per curve plus one"};
    if (hc.points.size() > (std::size_t(1) << 31))
        return Error{set + ": too many points (at most 2^31)"};
    if (auto e = check_curve_inputs(hc, set, materials[hc.material])) return *e;
    if (!hc.normals.empty() && hc.normals.size() != hc.points.size())
        return Error{set + ": normals has " + std::to_string(hc.normals.size()) +
                     " entries but points has " + std::to_string(hc.points.size()) +
                     " (one normal per point, or none)"};
    for (std::size_t k = 0; k < hc.normals.size(); ++k)
        if (!finite3(hc.normals[k]))
            return Error{set + ", point " + std::to_string(k) + ": normal must be finite (got " +
                         describe(hc.normals[k]) + ")"};
    return std::nullopt;
}

// Curve c's points b..e−1: finite positions and radii >= 0; its longest step and largest radius.
Status measure_curve(const HairCurves &hc, const std::string &set, std::size_t c, std::uint32_t b,
                     std::uint32_t e, float &max_step, float &max_radius) {
    max_step = 0;
    max_radius = 0;
    for (std::uint32_t k = b; k < e; ++k) {
        if (!finite3(hc.points[k]))
            return Error{set + ", curve " + std::to_string(c) + ", point " + std::to_string(k - b) +
                         ": position must be finite (got " + describe(hc.points[k]) + ")"};
        const float r = hc.radii[k];
        if (!std::isfinite(r) || r < 0.0f)
            return Error{set + ", curve " + std::to_string(c) + ", point " + std::to_string(k - b) +
                         ": radius must be finite and >= 0 (got " + std::to_string(r) + ")"};
        max_radius = std::max(max_radius, r);
        if (k > b) max_step = std::max(max_step, length(hc.points[k] - hc.points[k - 1]));
    }
    return std::nullopt;
}

// Curve c (points b..e−1) in Embree's layout: its control points with the end points repeated
// (a Catmull-Rom segment reads a point before and one after), its normals and inputs likewise,
// and a segment per pair of points.
void append_curve(CurveGeometry &geo, const HairCurves &hc, std::size_t c, std::uint32_t b, std::uint32_t e,
                  std::uint32_t curve_index) {
    const std::uint32_t base = std::uint32_t(geo.cvs.size());
    auto cv = [&](std::uint32_t k) { return Float4{hc.points[k].x, hc.points[k].y, hc.points[k].z, hc.radii[k]}; };
    geo.cvs.push_back(cv(b));
    for (std::uint32_t k = b; k < e; ++k) geo.cvs.push_back(cv(k));
    geo.cvs.push_back(cv(e - 1));
    if (!hc.normals.empty()) {
        geo.normals.push_back(hc.normals[b]);
        geo.normals.insert(geo.normals.end(), hc.normals.begin() + b, hc.normals.begin() + e);
        geo.normals.push_back(hc.normals[e - 1]);
    }
    for (std::size_t i = 0; i < hc.inputs.size(); ++i) {
        const std::size_t k = std::size_t(components_of(hc.inputs[i]));
        const std::vector<float> &from = hc.inputs[i].values;
        const std::size_t begin = hc.inputs[i].per_point ? b * k : c * k;
        const std::size_t end = hc.inputs[i].per_point ? e * k : (c + 1) * k;
        geo.inputs[i].values.insert(geo.inputs[i].values.end(), from.begin() + std::ptrdiff_t(begin),
                                    from.begin() + std::ptrdiff_t(end));
    }
    for (std::uint32_t k = 0; k + 1 < e - b; ++k) {
        geo.segments.push_back(base + k);
        geo.curve_of.push_back(curve_index);
    }
}

}  // namespace

Rgb material_emission(const Material &material) {
    if (const auto *d = std::get_if<DiffuseMaterial>(&material)) return d->emission;
    if (const auto *s = std::get_if<SurfaceMaterial>(&material)) return s->emission();
    return Rgb(0.0f);
}

struct Scene::Impl {
    RTCDevice device = nullptr;
    RTCScene rtc_scene = nullptr;
    std::vector<CurveGeometry> curves;
    std::vector<MeshGeometry> meshes;
    std::vector<GeometryInfo> geometries;  // by Embree geometry id
    std::vector<Material> materials;
    LightSet lights;
    std::optional<Camera> camera;
    SceneStats stats;
    CurveBackfaces curve_backfaces = CurveBackfaces::Ignore;
    CurveShape curve_shape = CurveShape::Thick;
    BvhQuality bvh_quality = BvhQuality::Medium;
    int curve_subdivisions = 2;

    std::vector<std::string> geometry_warnings;  // the build's, before the lights'
    std::size_t geometry_bytes = 0;              // stats.scene_bytes without the lights

    std::atomic<long long> embree_bytes{0};
    std::atomic<long long> embree_peak{0};
    std::mutex error_mutex;
    std::string embree_error;

    ~Impl() {
        if (rtc_scene) rtcReleaseScene(rtc_scene);
        if (device) rtcReleaseDevice(device);
    }

    static bool memory_monitor(void *user, ssize_t bytes, bool) {
        auto *self = static_cast<Impl *>(user);
        const long long now = self->embree_bytes.fetch_add(bytes) + bytes;
        long long peak = self->embree_peak.load();
        while (now > peak && !self->embree_peak.compare_exchange_weak(peak, now)) {
        }
        return true;  // never refuse an allocation
    }

    static void error_function(void *user, RTCError code, const char *message) {
        auto *self = static_cast<Impl *>(user);
        std::lock_guard<std::mutex> lock(self->error_mutex);
        if (self->embree_error.empty())
            self->embree_error = "Embree error " + std::to_string(int(code)) + ": " +
                                 (message ? message : "(no message)");
    }

    // The materials, lights and world of `desc` (its geometry is not read): checked against
    // the geometry's material indices and curve inputs, then the emissive triangles and the
    // light set made again. Leaves everything as it was when it refuses.
    Status set_shading(SceneDesc &desc) {
        if (auto e = check_materials(desc.materials)) return e;
        for (const CurveGeometry &geo : curves) {
            const std::string set = "curve set " + std::to_string(geo.set);
            if (auto e = check_material_index(desc.materials, set, geo.material, false)) return e;
            if (auto e = check_inputs_fit(geo.inputs, set, geo.material, desc.materials[geo.material])) return e;
        }
        for (const MeshGeometry &geo : meshes)
            for (std::uint32_t m : geo.materials)
                if (auto e = check_material_index(desc.materials, "mesh " + std::to_string(geo.mesh), m, true)) return e;
        std::vector<EmissiveTriangle> emissive;
        std::vector<std::vector<std::uint8_t>> flags(meshes.size());
        for (std::size_t i = 0; i < meshes.size(); ++i) {
            const MeshGeometry &geo = meshes[i];
            flags[i].assign(geo.materials.size(), 0);
            for (std::size_t t = 0; t < geo.materials.size(); ++t) {
                const Rgb radiance = material_emission(desc.materials[geo.materials[t]]);
                if (radiance.is_black()) continue;
                flags[i][t] = 1;
                auto vertex = [&](std::uint32_t k) {
                    return Vec3{geo.vertices[3 * k], geo.vertices[3 * k + 1], geo.vertices[3 * k + 2]};
                };
                EmissiveTriangle et;
                et.p0 = vertex(geo.indices[3 * t]);
                et.p1 = vertex(geo.indices[3 * t + 1]);
                et.p2 = vertex(geo.indices[3 * t + 2]);
                et.radiance = radiance;
                et.geometry = geo.geometry_id;
                et.primitive = std::uint32_t(t);
                emissive.push_back(et);
            }
        }
        std::vector<std::string> warnings = geometry_warnings;
        const std::size_t emissive_count = emissive.size();
        Expected<LightSet> made = LightSet::build(lights_of(desc), std::move(emissive), &warnings);
        if (!made) return made.error();
        for (std::size_t i = 0; i < meshes.size(); ++i) meshes[i].emissive = std::move(flags[i]);
        lights = std::move(made).value();
        materials = std::move(desc.materials);
        stats.warnings = std::move(warnings);
        stats.emissive_triangles = emissive_count;
        stats.lamps = std::size_t(lights.lamp_count());
        stats.scene_bytes = geometry_bytes + lights.memory_bytes();
        return std::nullopt;
    }

    Status add_curves(HairCurves &hc, std::size_t s, const std::vector<Material> &desc_materials);
    Status add_mesh(TriangleMesh &tm, std::size_t s, const std::vector<Material> &desc_materials);
    Status build_bvh();

    Status embree_status(const char *what) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (embree_error.empty() && device && rtcGetDeviceError(device) == RTC_ERROR_NONE)
            return std::nullopt;
        return Error{std::string("scene: ") + what + " failed: " +
                     (embree_error.empty() ? std::string("unknown Embree error") : embree_error)};
    }
};

Scene::Scene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Scene::Scene(Scene &&) noexcept = default;
Scene &Scene::operator=(Scene &&) noexcept = default;
Scene::~Scene() = default;

const Camera &Scene::camera() const { return *impl_->camera; }

Status Scene::set_camera(const CameraDesc &camera) {
    auto cam = Camera::create(camera);
    if (!cam) return cam.error();
    impl_->camera.emplace(std::move(cam).value());
    return std::nullopt;
}
const LightSet &Scene::lights() const { return impl_->lights; }
const std::vector<Material> &Scene::materials() const { return impl_->materials; }
const SceneStats &Scene::stats() const { return impl_->stats; }

// The kept curves of curve set `s` of a SceneDesc in Embree's layout, checked; the caller's
// buffers are freed.
Status Scene::Impl::add_curves(HairCurves &hc, std::size_t s, const std::vector<Material> &desc_materials) {
    const std::string set = "curve set " + std::to_string(s);
    if (auto e = check_curve_set(hc, set, desc_materials)) return *e;
    CurveGeometry geo;
    geo.material = hc.material;
    geo.set = s;
    for (const CurveInput &in : hc.inputs) geo.inputs.push_back({in.input, in.per_point, {}, in.closure_weight});
    std::size_t zero_length = 0, zero_radius = 0, stats_curves_in_set = 0;
    const std::size_t curve_count = hc.first.size() - 1;
    for (std::size_t c = 0; c < curve_count; ++c) {
        const std::uint32_t b = hc.first[c], e = hc.first[c + 1];
        if (e < b)
            return Error{set + ": first must not decrease (curve " + std::to_string(c) + ")"};
        const std::uint32_t n = e - b;
        if (n < 2)
            return Error{set + ", curve " + std::to_string(c) + ": has " + std::to_string(n) +
                         " point(s); a curve needs at least 2"};
        float max_step = 0, max_radius = 0;
        if (auto error = measure_curve(hc, set, c, b, e, max_step, max_radius)) return *error;
        if (!(max_step > 0.0f)) {
            ++zero_length;
            continue;
        }
        if (!(max_radius > 0.0f)) {
            ++zero_radius;
            continue;
        }
        append_curve(geo, hc, c, b, e, std::uint32_t(stats_curves_in_set++));
        ++stats.curves;
        stats.curve_points += n;
    }
    if (zero_length)
        stats.warnings.push_back(set + ": skipped " + std::to_string(zero_length) +
                                 " curve(s) of zero length");
    if (zero_radius)
        stats.warnings.push_back(set + ": skipped " + std::to_string(zero_radius) +
                                 " curve(s) of zero radius");
    stats.skipped_curves += zero_length + zero_radius;
    stats.curve_segments += geo.segments.size();
    // Free the caller's copy early: the scene keeps its own Embree layout.
    hc.points = {};
    hc.radii = {};
    hc.first = {};
    hc.inputs = {};
    hc.normals = {};
    if (!geo.segments.empty()) curves.push_back(std::move(geo));
    return std::nullopt;
}

// The kept triangles of mesh `s` of a SceneDesc, checked; the caller's buffers are freed.
Status Scene::Impl::add_mesh(TriangleMesh &tm, std::size_t s, const std::vector<Material> &desc_materials) {
    const std::string name = "mesh " + std::to_string(s);
    if (tm.indices.size() % 3 != 0)
        return Error{name + ": indices has " + std::to_string(tm.indices.size()) +
                     " entries, not a multiple of 3"};
    const std::size_t tri_count = tm.indices.size() / 3;
    if (tm.materials.size() != 1 && tm.materials.size() != tri_count)
        return Error{name + ": materials must hold 1 entry or one per triangle (" +
                     std::to_string(tri_count) + "), got " +
                     std::to_string(tm.materials.size())};
    for (std::size_t v = 0; v < tm.positions.size(); ++v)
        if (!finite3(tm.positions[v]))
            return Error{name + ", vertex " + std::to_string(v) +
                         ": position must be finite (got " + describe(tm.positions[v]) + ")"};
    for (std::uint32_t m : tm.materials)
        if (auto e = check_material_index(desc_materials, name, m, true)) return *e;
    if (!tm.normals.empty() && tm.normals.size() != tm.indices.size())
        return Error{name + ": normals has " + std::to_string(tm.normals.size()) +
                     " entries; it needs one per triangle corner (" +
                     std::to_string(tm.indices.size()) + ") or none"};
    if (!tm.uvs.empty() && tm.uvs.size() != 2 * tm.indices.size())
        return Error{name + ": uvs has " + std::to_string(tm.uvs.size()) +
                     " floats; it needs a (u, v) pair per triangle corner (" +
                     std::to_string(2 * tm.indices.size()) + " floats) or none"};
    for (std::size_t k = 0; k < tm.normals.size(); ++k)
        if (!finite3(tm.normals[k]) || !(length(tm.normals[k]) > 0.0f))
            return Error{name + ", corner " + std::to_string(k) +
                         ": normal must be finite and not zero (got " + describe(tm.normals[k]) + ")"};
    for (std::size_t k = 0; k < tm.uvs.size(); ++k)
        if (!std::isfinite(tm.uvs[k]))
            return Error{name + ", corner " + std::to_string(k / 2) + ": uv must be finite"};
    MeshGeometry geo;
    geo.mesh = s;
    std::size_t degenerate = 0;
    for (std::size_t t = 0; t < tri_count; ++t) {
        const std::uint32_t i0 = tm.indices[3 * t], i1 = tm.indices[3 * t + 1],
                            i2 = tm.indices[3 * t + 2];
        if (i0 >= tm.positions.size() || i1 >= tm.positions.size() ||
            i2 >= tm.positions.size())
            return Error{name + ", triangle " + std::to_string(t) +
                         ": vertex index out of range (the mesh has " +
                         std::to_string(tm.positions.size()) + " vertices)"};
        const Vec3 p0 = tm.positions[i0], p1 = tm.positions[i1], p2 = tm.positions[i2];
        if (!(length(cross(p1 - p0, p2 - p0)) > 0.0f)) {
            ++degenerate;
            continue;
        }
        geo.indices.insert(geo.indices.end(), {i0, i1, i2});
        geo.materials.push_back(tm.materials.size() == 1 ? tm.materials[0] : tm.materials[t]);
        if (!tm.normals.empty())
            for (int k = 0; k < 3; ++k) geo.normals.push_back(safe_normalize(tm.normals[3 * t + k]));
        if (!tm.uvs.empty()) geo.uvs.insert(geo.uvs.end(), &tm.uvs[6 * t], &tm.uvs[6 * t] + 6);
    }
    if (degenerate) {
        stats.warnings.push_back(name + ": skipped " + std::to_string(degenerate) +
                                 " degenerate triangle(s)");
        stats.skipped_triangles += degenerate;
    }
    if (geo.indices.empty()) return std::nullopt;
    geo.vertices.reserve(3 * tm.positions.size() + 1);
    for (const Vec3 &p : tm.positions) geo.vertices.insert(geo.vertices.end(), {p.x, p.y, p.z});
    geo.vertices.push_back(0.0f);  // Embree reads float3 vertices with 16-byte loads
    stats.triangles += geo.materials.size();
    tm = {};
    meshes.push_back(std::move(geo));
    return std::nullopt;
}

// Embree's device, scene and BVH over the curves and meshes added, and their memory.
Status Scene::Impl::build_bvh() {
    device = rtcNewDevice(nullptr);
    if (!device)
        return Error{"scene: could not create the Embree device (error " +
                     std::to_string(int(rtcGetDeviceError(nullptr))) + ")"};
    rtcSetDeviceErrorFunction(device, &Impl::error_function, this);
    rtcSetDeviceMemoryMonitorFunction(device, &Impl::memory_monitor, this);
    rtc_scene = rtcNewScene(device);
    rtcSetSceneFlags(rtc_scene, bvh_quality == BvhQuality::Low ? RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_DYNAMIC
                                                               : RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(rtc_scene, bvh_quality == BvhQuality::Low    ? RTC_BUILD_QUALITY_LOW
                                       : bvh_quality == BvhQuality::High ? RTC_BUILD_QUALITY_HIGH
                                                                         : RTC_BUILD_QUALITY_MEDIUM);

    const CurveShape shape = curve_shape;
    const RTCGeometryType curve_type = shape == CurveShape::Ribbons ? RTC_GEOMETRY_TYPE_FLAT_CATMULL_ROM_CURVE
                                       : shape == CurveShape::ThickLinear ? RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE
                                                                          : RTC_GEOMETRY_TYPE_ROUND_CATMULL_ROM_CURVE;
    const RTCFilterFunctionN filter = shape == CurveShape::Ribbons       ? &curve_filter<InsideHits::NoInside>
                                      : shape == CurveShape::ThickLinear ? &curve_filter<InsideHits::Culled>
                                                                         : &curve_filter<InsideHits::AsContext>;
    // Linear segments start one control point on: segment index k reads points k and k + 1
    // past the leading duplicate.
    const std::size_t skip = shape == CurveShape::ThickLinear ? 1 : 0;
    for (std::size_t i = 0; i < curves.size(); ++i) {
        CurveGeometry &geo = curves[i];
        RTCGeometry g = rtcNewGeometry(device, curve_type);
        rtcSetGeometryTessellationRate(g, float(std::clamp(1 << curve_subdivisions, 1, 16) + 1));
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, geo.cvs.data(),
                                   skip * sizeof(Float4), sizeof(Float4), geo.cvs.size() - skip);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                   geo.segments.data(), 0, sizeof(std::uint32_t),
                                   geo.segments.size());
        rtcSetGeometryUserData(g, geo.curve_of.data());
        rtcSetGeometryIntersectFilterFunction(g, filter);
        rtcSetGeometryOccludedFilterFunction(g, filter);
        rtcCommitGeometry(g);
        const unsigned id = rtcAttachGeometry(rtc_scene, g);
        rtcReleaseGeometry(g);
        if (geometries.size() <= id) geometries.resize(id + 1);
        geometries[id] = {true, std::uint32_t(i)};
    }
    for (std::size_t i = 0; i < meshes.size(); ++i) {
        MeshGeometry &geo = meshes[i];
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                   geo.vertices.data(), 0, 3 * sizeof(float),
                                   (geo.vertices.size() - 1) / 3);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                   geo.indices.data(), 0, 3 * sizeof(std::uint32_t),
                                   geo.indices.size() / 3);
        rtcSetGeometryIntersectFilterFunction(g, &triangle_filter);
        rtcSetGeometryOccludedFilterFunction(g, &triangle_filter);
        rtcCommitGeometry(g);
        const unsigned id = rtcAttachGeometry(rtc_scene, g);
        rtcReleaseGeometry(g);
        if (geometries.size() <= id) geometries.resize(id + 1);
        geometries[id] = {false, std::uint32_t(i)};
        geo.geometry_id = id;
    }
    rtcCommitScene(rtc_scene);
    if (auto e = embree_status("building the BVH")) return e;
    std::size_t bytes = sizeof(Impl) + geometries.capacity() * sizeof(GeometryInfo);
    for (const auto &c : curves) {
        bytes += c.cvs.capacity() * sizeof(Float4) + c.segments.capacity() * 4 +
                 c.curve_of.capacity() * 4 + c.normals.capacity() * sizeof(Vec3);
        for (const CurveInput &in : c.inputs) bytes += in.values.capacity() * sizeof(float);
    }
    for (const auto &m : meshes)
        bytes += m.vertices.capacity() * 4 + m.indices.capacity() * 4 +
                 m.materials.capacity() * 4 + m.materials.size() +
                 m.normals.capacity() * sizeof(Vec3) + m.uvs.capacity() * 4;
    geometry_bytes = bytes;
    return std::nullopt;
}

Expected<Scene> Scene::build(SceneDesc desc) {
    const auto start = std::chrono::steady_clock::now();
    auto impl = std::make_unique<Impl>();
    SceneStats &stats = impl->stats;
    if (desc.curve_backfaces != CurveBackfaces::Ignore &&
        desc.curve_backfaces != CurveBackfaces::Hit)
        return Error{"curve_backfaces must be ignore (0) or hit (1) (got " +
                     std::to_string(int(desc.curve_backfaces)) + ")"};
    impl->curve_backfaces = desc.curve_backfaces;
    if (desc.curve_shape != CurveShape::Thick && desc.curve_shape != CurveShape::Ribbons &&
        desc.curve_shape != CurveShape::ThickLinear)
        return Error{"curve_shape must be thick (0), ribbons (1) or thick_linear (2) (got " +
                     std::to_string(int(desc.curve_shape)) + ")"};
    impl->curve_shape = desc.curve_shape;
    if (desc.bvh_quality != BvhQuality::Low && desc.bvh_quality != BvhQuality::Medium &&
        desc.bvh_quality != BvhQuality::High)
        return Error{"bvh_quality must be low (0), medium (1) or high (2) (got " +
                     std::to_string(int(desc.bvh_quality)) + ")"};
    impl->bvh_quality = desc.bvh_quality;
    if (desc.curve_subdivisions < 0 || desc.curve_subdivisions > 24)
        return Error{"curve_subdivisions must be in [0, 24] (got " + std::to_string(desc.curve_subdivisions) + ")"};
    impl->curve_subdivisions = desc.curve_subdivisions;

    if (auto e = check_materials(desc.materials)) return *e;

    // Lights: validated now (cheap) so that a bad light fails before the BVH is built; the
    // light set itself is built at the end, with the emissive triangles.
    {
        auto lights = LightSet::build(lights_of(desc), {}, nullptr);
        if (!lights) return lights.error();
    }

    // Camera.
    {
        auto cam = Camera::create(desc.camera);
        if (!cam) return cam.error();
        impl->camera.emplace(std::move(cam).value());
    }

    for (std::size_t s = 0; s < desc.curves.size(); ++s)
        if (auto e = impl->add_curves(desc.curves[s], s, desc.materials)) return *e;
    for (std::size_t s = 0; s < desc.meshes.size(); ++s)
        if (auto e = impl->add_mesh(desc.meshes[s], s, desc.materials)) return *e;
    // A scene with no geometry left is legal, as in Cycles: every ray misses and the render
    // shows the world.
    if (auto e = impl->build_bvh()) return *e;

    // Materials and lights, as set_shading sets them again.
    impl->geometry_warnings = stats.warnings;
    if (auto e = impl->set_shading(desc)) return *e;
    stats.embree_peak_bytes = std::size_t(std::max(0ll, impl->embree_peak.load()));
    stats.embree_bytes = std::size_t(std::max(0ll, impl->embree_bytes.load()));
    stats.estimated_peak_bytes = stats.scene_bytes + stats.embree_peak_bytes;
    stats.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return Scene(std::move(impl));
}

Status Scene::set_shading(SceneDesc desc) { return impl_->set_shading(desc); }

namespace {

// Embree's own precondition on a ray (RayK::valid(), asserted in Debian's build): origin and
// direction components within ±1.844e18 (FLT_LARGE), t range not NaN. Rays outside it come
// from finite but astronomically large inputs (a camera or vertex at 1e30) and are not
// traced: a miss for intersect, blocked for shadow rays (found by fuzz_capi_params).
bool traceable(Vec3 origin, Vec3 dir, float tmin, float tmax) {
    constexpr float kLarge = 1.844e18f;
    for (float c : {origin.x, origin.y, origin.z, dir.x, dir.y, dir.z})
        if (!(std::fabs(c) <= kLarge)) return false;
    return !std::isnan(tmin) && !std::isnan(tmax);
}

}  // namespace

namespace {

// An Embree ray (origin, dir) over [tmin, tmax] with no hit yet.
RTCRayHit ray_hit(Vec3 origin, Vec3 dir, float tmin, float tmax) {
    RTCRayHit rh{};
    rh.ray.org_x = origin.x;
    rh.ray.org_y = origin.y;
    rh.ray.org_z = origin.z;
    rh.ray.tnear = tmin;
    rh.ray.dir_x = dir.x;
    rh.ray.dir_y = dir.y;
    rh.ray.dir_z = dir.z;
    rh.ray.tfar = tmax;
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

}  // namespace

std::optional<Hit> Scene::intersect(Vec3 origin, Vec3 dir, float tmin, float tmax,
                                    PrimRef skip) const {
    if (!traceable(origin, dir, tmin, tmax)) return std::nullopt;
    TraceContext ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.skip_a = skip;
    ctx.hit_curve_backfaces = impl_->curve_backfaces == CurveBackfaces::Hit;
    RTCRayHit rh = ray_hit(origin, dir, tmin, tmax);
    rtcIntersect1(impl_->rtc_scene, &ctx.rtc, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    Hit hit;
    hit.t = rh.ray.tfar;
    hit.prim = {rh.hit.geomID, rh.hit.primID};
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    return hit;
}

bool Scene::occluded(Vec3 origin, Vec3 dir, float tmin, float tmax, PrimRef skip_a,
                     PrimRef skip_b) const {
    if (!traceable(origin, dir, tmin, tmax)) return true;
    TraceContext ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.skip_a = skip_a;
    ctx.hit_curve_backfaces = impl_->curve_backfaces == CurveBackfaces::Hit;
    ctx.skip_b = skip_b;
    RTCRay ray = ray_hit(origin, dir, tmin, tmax).ray;
    rtcOccluded1(impl_->rtc_scene, &ctx.rtc, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar to −inf on a hit
}

std::optional<Hit> Scene::trace_through_hair(Vec3 origin, Vec3 dir, float tmin, float tmax,
                                             PrimRef skip_a, PrimRef skip_b,
                                             std::vector<StrandCrossing> &strands) const {
    bool stopped = false;
    return trace_through_hair(origin, dir, tmin, tmax, skip_a, skip_b, strands,
                              std::numeric_limits<std::size_t>::max(), stopped);
}

std::optional<Hit> Scene::trace_through_hair(Vec3 origin, Vec3 dir, float tmin, float tmax,
                                             PrimRef skip_a, PrimRef skip_b,
                                             std::vector<StrandCrossing> &strands,
                                             std::size_t accept_after, bool &stopped) const {
    strands.clear();
    stopped = false;
    if (!traceable(origin, dir, tmin, tmax)) return Hit{tmin, PrimRef{}, 0.0f, 0.0f};  // blocked
    TraceContext ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.skip_a = skip_a;
    ctx.skip_b = skip_b;
    ctx.strands = &strands;
    ctx.accept_after = accept_after;
    RTCRayHit rh = ray_hit(origin, dir, tmin, tmax);
    rtcIntersect1(impl_->rtc_scene, &ctx.rtc, &rh);
    std::optional<Hit> mesh;
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
        // An accepted curve hit: the traversal stopped there, with no mesh before it.
        stopped = impl_->geometries[rh.hit.geomID].is_curve;
        if (!stopped) mesh = Hit{rh.ray.tfar, {rh.hit.geomID, rh.hit.primID}, rh.hit.u, rh.hit.v};
    }

    // Hair hits recorded before a nearer triangle (or accepted curve) was found lie behind it.
    const float t_end = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar : tmax;
    strands.erase(std::remove_if(strands.begin(), strands.end(),
                                 [&](const StrandCrossing &c) { return !(c.t < t_end); }),
                  strands.end());
    std::sort(strands.begin(), strands.end(),
              [](const StrandCrossing &a, const StrandCrossing &b) { return a.t < b.t; });
    // One entry per crossing: where neighbouring segments of a curve overlap at their joint
    // (or a primitive is reported twice) the hits lie within a tube's chord of each other.
    std::size_t kept = 0;
    for (std::size_t k = 0; k < strands.size(); ++k) {
        StrandCrossing c = strands[k];
        const GeometryInfo &info = impl_->geometries[c.segment.geometry];
        const CurveGeometry &geo = impl_->curves[info.index];
        Vec3 dpdu;
        curve_point(c.segment, c.u, &dpdu, &c.radius);
        c.tangent = safe_normalize(dpdu);
        if (dot(c.tangent, c.tangent) == 0.0f) {
            const std::uint32_t first = geo.segments[c.segment.primitive];
            const Float4 &a = geo.cvs[first + 1], &b = geo.cvs[first + 2];
            c.tangent = safe_normalize(Vec3{b.x - a.x, b.y - a.y, b.z - a.z});
        }
        c.material = geo.material;
        const float sin_cross = std::max(length(cross(dir, c.tangent)), 0.05f);
        bool duplicate = false;
        for (std::size_t j = kept; j-- > 0 && kept - j <= 4;) {
            const StrandCrossing &prev = strands[j];
            if (prev.segment.geometry != c.segment.geometry) continue;
            const std::uint32_t pa = prev.segment.primitive, pb = c.segment.primitive;
            if (geo.curve_of[pa] != geo.curve_of[pb] || (pa > pb ? pa - pb : pb - pa) > 1) continue;
            if (c.t - prev.t < 2.0f * (c.radius + prev.radius) / sin_cross) {
                duplicate = true;
                break;
            }
        }
        if (duplicate) continue;
        strands[kept++] = c;
    }
    strands.resize(kept);
    return mesh;
}

std::optional<Hit> Scene::trace_through_hair_within(Vec3 origin, Vec3 dir, float tmin, float tmax,
                                                    PrimRef skip_a, PrimRef skip_b, int cap,
                                                    std::vector<StrandCrossing> &strands) const {
    if (cap < 0) return trace_through_hair(origin, dir, tmin, tmax, skip_a, skip_b, strands);
    // A crossing may leave two records (a joint of two segments): 2·(cap + 1) records hold at
    // least cap + 1 crossings but for repeats, which the full trace below covers.
    const std::size_t enough = std::size_t(cap) + 1;
    bool stopped = false;
    std::optional<Hit> mesh =
        trace_through_hair(origin, dir, tmin, tmax, skip_a, skip_b, strands, 2 * enough, stopped);
    if (stopped && strands.size() < enough)
        mesh = trace_through_hair(origin, dir, tmin, tmax, skip_a, skip_b, strands);
    if (strands.size() < enough) return mesh;
    strands.resize(enough);
    return std::nullopt;
}

int Scene::strands_before_mesh(Vec3 origin, Vec3 dir, float tmin, float tmax, PrimRef skip, int cap,
                               std::vector<StrandCrossing> &scratch) const {
    cap = std::max(cap, 1);
    trace_through_hair_within(origin, dir, tmin, tmax, skip, {}, cap - 1, scratch);
    return std::min(int(scratch.size()), cap);
}

Vec3 Scene::curve_point(PrimRef segment, float u, Vec3 *derivative, float *radius) const {
    const GeometryInfo &info = impl_->geometries.at(segment.geometry);
    const CurveGeometry &geo = impl_->curves.at(info.index);
    const std::uint32_t k = geo.segments.at(segment.primitive);
    Float4 value, d;
    if (impl_->curve_shape == CurveShape::ThickLinear)
        linear(geo.cvs[k + 1], geo.cvs[k + 2], u, value, d);
    else
        catmull_rom(geo.cvs[k], geo.cvs[k + 1], geo.cvs[k + 2], geo.cvs[k + 3], u, value, d);
    if (derivative) *derivative = {d.x, d.y, d.z};
    if (radius) *radius = value.w;
    return {value.x, value.y, value.z};
}

SurfacePoint Scene::surface_point(Vec3 origin, Vec3 dir, const Hit &hit) const {
    SurfacePoint sp;
    sp.prim = hit.prim;
    sp.position = origin + dir * hit.t;
    const GeometryInfo &info = impl_->geometries[hit.prim.geometry];
    if (info.is_curve) {
        const CurveGeometry &geo = impl_->curves[info.index];
        Vec3 dpdu;
        const Vec3 centre = curve_point(hit.prim, hit.u, &dpdu);
        sp.is_curve = true;
        sp.curve_u = std::clamp(hit.u, 0.0f, 1.0f);
        sp.self = {hit.prim.geometry, geo.curve_of[hit.prim.primitive]};
        sp.material = geo.material;
        if (impl_->curve_shape == CurveShape::Ribbons) {
            sp.normal = -dir;
            sp.is_ribbon = true;
            sp.curve_v = std::clamp(hit.v, -1.0f, 1.0f);
        } else {
            const Vec3 n = safe_normalize(sp.position - centre);
            sp.normal = dot(n, n) > 0.0f ? n : -dir;
        }
        sp.shading_normal = sp.normal;
        // Per-point attributes between the segment's two points (Cycles' curve_attribute).
        const std::uint32_t key = geo.segments[hit.prim.primitive] + 1;
        const float u = hit.u;
        sp.curve_radius = (1.0f - u) * geo.cvs[key].w + u * geo.cvs[key + 1].w;
        if (!geo.normals.empty()) sp.curve_normal = geo.normals[key] * (1.0f - u) + geo.normals[key + 1] * u;
        sp.tangent = safe_normalize(dpdu);
        if (dot(sp.tangent, sp.tangent) == 0.0f) {
            // dP/du vanishes (repeated points): the chord, or any direction across the normal.
            const std::uint32_t k = geo.segments[hit.prim.primitive];
            const Float4 &a = geo.cvs[k + 1], &b = geo.cvs[k + 2];
            sp.tangent = safe_normalize(Vec3{b.x - a.x, b.y - a.y, b.z - a.z});
            if (dot(sp.tangent, sp.tangent) == 0.0f) {
                Vec3 t1, t2;
                orthonormal_basis(sp.normal, t1, t2);
                sp.tangent = t1;
            }
        }
        if (sp.is_ribbon) {
            // Cycles' rounded ribbon normal: sine v towards the strip's edge, cosine towards −dir.
            const Vec3 bitangent = safe_normalize(cross(sp.tangent, -dir));
            const Vec3 towards = safe_normalize(cross(sp.tangent, bitangent));
            const float sine = sp.curve_v, cosine = std::sqrt(std::max(0.0f, 1.0f - sine * sine));
            const Vec3 n = safe_normalize(bitangent * sine - towards * cosine);
            if (dot(n, n) > 0.0f) sp.shading_normal = n;
        }
    } else {
        const MeshGeometry &geo = impl_->meshes[info.index];
        const std::uint32_t t = hit.prim.primitive;
        auto vertex = [&](std::uint32_t k) {
            return Vec3{geo.vertices[3 * k], geo.vertices[3 * k + 1], geo.vertices[3 * k + 2]};
        };
        const Vec3 p0 = vertex(geo.indices[3 * t]), p1 = vertex(geo.indices[3 * t + 1]),
                   p2 = vertex(geo.indices[3 * t + 2]);
        sp.normal = safe_normalize(cross(p1 - p0, p2 - p0));
        // The position from Embree's barycentrics (more accurate than origin + t·dir) and a
        // bound on its rounding error, a few float ulps of the largest coordinate involved.
        const float u = hit.u, v = hit.v;
        sp.position = p0 * (1.0f - u - v) + p1 * u + p2 * v;
        float extent = 0.0f;
        for (const Vec3 &q : {p0, p1, p2, sp.position})
            extent = std::max({extent, std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
        sp.offset = 2e-6f * extent + 1e-9f;
        const float w0 = 1.0f - u - v;
        sp.shading_normal = sp.normal;
        if (!geo.normals.empty()) {
            const Vec3 *c = &geo.normals[3 * std::size_t(t)];
            const Vec3 n = safe_normalize(c[0] * w0 + c[1] * u + c[2] * v);
            if (dot(n, n) > 0.0f) sp.shading_normal = n;
        }
        if (!geo.uvs.empty()) {
            const float *c = &geo.uvs[6 * std::size_t(t)];
            sp.u = c[0] * w0 + c[2] * u + c[4] * v;
            sp.v = c[1] * w0 + c[3] * u + c[5] * v;
        }
        sp.material = geo.materials[t];
        sp.is_light = geo.emissive[t] != 0;
        sp.self = hit.prim;
    }
    return sp;
}

bool Scene::hair_inputs(const SurfacePoint &point, HairInputValues &values, ClosureWeights *weights) const {
    if (!point.is_curve) return false;
    const GeometryInfo &info = impl_->geometries[point.prim.geometry];
    const CurveGeometry &geo = impl_->curves[info.index];
    if (geo.inputs.empty()) return false;
    const std::uint32_t segment = point.prim.primitive;
    const std::size_t curve = geo.curve_of[segment];
    // Kept curve j's control points start at (its points' offset) + 2j: one duplicate at each end.
    const std::size_t first_point = std::size_t(geo.segments[segment]) - 2 * curve;
    const float u = point.curve_u;
    for (const CurveInput &in : geo.inputs) {
        const int k = components_of(in);
        float v[3];
        if (in.per_point) {
            const float *a = in.values.data() + first_point * std::size_t(k), *b = a + k;
            // Between the two points' values, whatever the rounding: ranges stay ranges.
            for (int c = 0; c < k; ++c)
                v[c] = std::clamp(a[c] + u * (b[c] - a[c]), std::min(a[c], b[c]), std::max(a[c], b[c]));
        } else {
            const float *a = in.values.data() + curve * std::size_t(k);
            for (int c = 0; c < k; ++c) v[c] = a[c];
        }
        if (in.closure_weight < 0) {
            values.set(in.input, v);
        } else if (weights) {
            weights->given |= 1u << unsigned(in.closure_weight);
            weights->value[std::size_t(in.closure_weight)] = v[0];
        }
    }
    return true;
}

}  // namespace hairis
