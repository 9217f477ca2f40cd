#include "render/dual_scattering_integrator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <variant>

namespace hairis {

namespace {

float clamp_unit(float s) { return std::clamp(s, -1.0f, 1.0f); }

// Adds one crossed strand to the forward scattering of light travelling along −dir.
void add_crossing(ForwardScattering &forward, const Scene &scene, const StrandCrossing &c,
                  Vec3 dir, const DualScattering &fallback) {
    const DualScattering *dual = &fallback;
    if (c.material < scene.materials().size())
        if (const auto *hair = std::get_if<HairMaterial>(&scene.materials()[c.material]))
            if (hair->dual) dual = hair->dual.get();
    const double theta = safe_asin(dot(dir, c.tangent));
    forward.attenuation *= dual->crossing_attenuation(theta);
    forward.spread_variance += dual->forward_spread_variance(theta, 1);
    ++forward.strands;
}

// A unit direction uniform on the sphere.
Vec3 uniform_sphere(float u0, float u1) {
    const float z = 1.0f - 2.0f * u0;
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = float(kTwoPi) * u1;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

float shadow_tmax(const LightSample &ls) {
    return std::isinf(ls.distance) ? INFINITY : ls.distance * (1.0f - 1e-5f);
}

bool same_ray(const LightSample &a, const LightSample &b) {
    return a.wi.x == b.wi.x && a.wi.y == b.wi.y && a.wi.z == b.wi.z && a.distance == b.distance &&
           a.skip_geometry == b.skip_geometry && a.skip_primitive == b.skip_primitive;
}

}  // namespace

int StrandsBehind::depth(const Scene &scene, int strands, int bounces_left,
                         std::vector<StrandCrossing> &scratch, std::uint64_t &rays) {
    if (!layer) return -1;
    if (backscatter_depth(-1, strands, bounces_left) == 0) return 0;
    if (counted < 0) {
        counted = scene.strands_before_mesh(origin, dir, 0.0f, INFINITY, self,
                                            std::clamp(cap, 1, kMaxStrandsBehind), scratch);
        ++rays;
    }
    return counted;
}

ForwardScattering gather_forward_scattering(const Scene &scene, const StrandCrossing *strands,
                                            std::size_t count, Vec3 dir,
                                            const DualScattering &fallback) {
    ForwardScattering forward;
    for (std::size_t k = 0; k < count; ++k) add_crossing(forward, scene, strands[k], dir, fallback);
    return forward;
}

int backscatter_depth(int depth, int strands, int bounces_left) {
    if (bounces_left < 0) return depth;
    const int limit = bounces_left > strands ? (bounces_left - strands) / 2 : 0;
    return depth < 0 ? limit : std::min(depth, limit);
}

Rgb dual_multiple_f_cos(const DualScattering &dual, float theta_i, float theta_o,
                        const ForwardScattering &forward, int depth, int bounces_left) {
    if (bounces_left >= 0 && forward.strands > bounces_left) return Rgb(0.0f);
    const int cut = backscatter_depth(depth, forward.strands, bounces_left);
    if (forward.strands == 0) return dual.local_f_cos(theta_i, theta_o, cut);
    return dual.scattered_f_cos(theta_i, theta_o, forward.attenuation * dual.params().d_f,
                                forward.spread_variance, cut);
}

int nearest_strand_index(const MultipleTable &table, int strands) {
    const std::vector<int> &values = table.n_h_values();
    const double target = std::log2(double(std::max(strands, 1)));
    int best = 0;
    double best_distance = INFINITY;
    for (std::size_t k = 0; k < values.size(); ++k) {
        const double d = std::fabs(std::log2(double(values[k])) - target);
        if (d < best_distance) {
            best_distance = d;
            best = int(k);
        }
    }
    return best;
}

MultipleTableSample sample_multiple_table(const MultipleTable &table, int strand,
                                          const FiberFrame &frame, Vec3 wo_local, float u0,
                                          float u1, float u2) {
    const float theta_o = safe_asin(wo_local.x);
    const TableSample s = table.sample(strand, theta_o, u0, u1, u2);
    if (!(s.pdf > 0.0f)) return {};
    // The view's azimuth in the fiber frame (Cycles' frame: φ_o = −π/2).
    const float cos_o = std::sqrt(wo_local.y * wo_local.y + wo_local.z * wo_local.z);
    const float cos_phi_o = cos_o > 0.0f ? wo_local.y / cos_o : 0.0f;
    const float sin_phi_o = cos_o > 0.0f ? wo_local.z / cos_o : -1.0f;
    const Vec3 wi = safe_normalize(frame.to_world(s.local_direction(cos_phi_o, sin_phi_o)));
    if (!(dot(wi, wi) > 0.0f)) return {};
    return {wi, s.sin_theta_i, s.pdf};
}

float multiple_table_pdf(const MultipleTable &table, int strand, const FiberFrame &frame,
                         Vec3 wo_local, Vec3 wi) {
    const float theta_o = safe_asin(wo_local.x);
    return table.pdf_sin(strand, theta_o, clamp_unit(frame.to_local(wi).x));
}

Rgb dual_scattering_light(const Scene &scene, const DualVertex &v, const DualRandom &u,
                          DualWork &work) {
    const SurfacePoint &sp = *v.point;
    const DualScattering &dual = *v.material->dual;
    const MultipleTable &table = *v.material->multiple;
    const LightSet &lights = scene.lights();
    const Vec3 wo_local = v.frame.to_local(v.wo);
    const float theta_o = safe_asin(wo_local.x);
    Rgb out;

    // The n_h probe: strands towards an independently drawn light point.
    std::optional<LightSample> probe;
    if (!lights.empty()) probe = lights.sample(sp.position, u.probe_select, u.probe_u, u.probe_v);
    if (probe && !(probe->pdf > 0.0f)) probe.reset();
    std::optional<Hit> probe_mesh;
    {
        const Vec3 dir = probe ? probe->wi : uniform_sphere(u.probe_u, u.probe_v);
        const float tmax = probe ? shadow_tmax(*probe) : INFINITY;
        const PrimRef target = probe ? PrimRef{probe->skip_geometry, probe->skip_primitive} : PrimRef{};
        probe_mesh = scene.trace_through_hair_within(sp.spawn_point(dir), dir, 0.0f, tmax, sp.self, target,
                                                     v.bounces_left, work.probe);
        ++work.rays;
    }
    // The strands behind the vertex along the travel of light from ω_i, −ω_i, where Ā_b's
    // series stop for that light (Layer), counted up to strands_behind_cap when a term needs it.
    auto behind = [&](Vec3 wi) {
        return StrandsBehind{sp.spawn_point(-wi), -wi, sp.self, strands_behind_cap(v.bounces_left), v.layer};
    };
    // The continuation's (the caller's): behind the vertex away from the probe's light point.
    work.last_depth = behind(probe ? probe->wi : uniform_sphere(u.probe_u, u.probe_v));
    const int strand = nearest_strand_index(table, int(work.probe.size()));
    work.last_strand_index = strand;
    work.last_probe_strands = int(work.probe.size());

    // Light sampling: D against the material's sampler, M against the multiple table.
    if (!lights.empty()) {
        const std::optional<LightSample> ls =
            lights.sample(sp.position, u.light_select, u.light_u, u.light_v);
        if (ls && ls->pdf > 0.0f) {
            const std::vector<StrandCrossing> *crossings = &work.probe;
            std::optional<Hit> mesh = probe_mesh;
            if (!(probe && probe->delta && ls->delta && same_ray(*probe, *ls))) {
                mesh = scene.trace_through_hair_within(sp.spawn_point(ls->wi), ls->wi, 0.0f, shadow_tmax(*ls),
                                                       sp.self, {ls->skip_geometry, ls->skip_primitive},
                                                       v.bounces_left, work.light);
                ++work.rays;
                crossings = &work.light;
            }
            if (!mesh) {
                const Vec3 l = v.frame.to_local(ls->wi);
                const float theta_i = safe_asin(l.x);
                const ForwardScattering forward =
                    gather_forward_scattering(scene, crossings->data(), crossings->size(), ls->wi, dual);
                Rgb sum;
                const float pdf_table = multiple_table_pdf(table, strand, v.frame, wo_local, ls->wi);
                if (forward.strands == 0) {
                    float pdf_bsdf = 0.0f;
                    const Rgb f = v.bsdf->f_and_pdf(l, pdf_bsdf);
                    if (v.layer) pdf_bsdf = dual_mixture_pdf(pdf_bsdf, pdf_table);
                    sum += f * (ls->delta ? 1.0f : power_heuristic(ls->pdf, pdf_bsdf));
                }
                // The probe's count is this sample's when both drew the same delta light.
                StrandsBehind along_light = behind(ls->wi);
                StrandsBehind &light_behind = crossings == &work.probe ? work.last_depth : along_light;
                const int light_depth =
                    light_behind.depth(scene, forward.strands, v.bounces_left, work.behind, work.rays);
                const Rgb m = dual_multiple_f_cos(dual, theta_i, theta_o, forward, light_depth, v.bounces_left);
                sum += m * (ls->delta ? 1.0f : power_heuristic(ls->pdf, pdf_table));
                out += sum * ls->value / ls->pdf;
            }
        }
    }

    // Multiple-table sampling of M.
    const MultipleTableSample s =
        sample_multiple_table(table, strand, v.frame, wo_local, u.table_u0, u.table_u1, u.table_u2);
    if (s.pdf > 0.0f) {
        const Vec3 wi = s.wi;
        const Vec3 origin = sp.spawn_point(wi);
        const std::optional<Hit> mesh =
            scene.trace_through_hair_within(origin, wi, 0.0f, INFINITY, sp.self, {}, v.bounces_left, work.table);
        ++work.rays;
        // Past the first bounces_left + 1 strands nothing reaches x within the limit.
        const bool over = v.bounces_left >= 0 && work.table.size() > std::size_t(v.bounces_left);
        const float theta_i = safe_asin(s.sin_theta_i);
        const float t_end = over ? work.table.back().t : mesh ? mesh->t : INFINITY;
        const float inv_pdf = 1.0f / s.pdf;
        // The strands behind along −ω_i, counted once, when light first arrives (work.table
        // stays); later light has crossed more strands, so its cut is no deeper.
        StrandsBehind table_behind = behind(wi);
        auto sample_depth = [&](int strands) {
            return table_behind.depth(scene, strands, v.bounces_left, work.behind, work.rays);
        };
        // Lamps between crossings see the strands before them.
        ForwardScattering forward;
        float t_lo = 0.0f;
        for (std::size_t k = 0; k <= work.table.size(); ++k) {
            const float t_hi = k < work.table.size() ? work.table[k].t : t_end;
            const Rgb lamps = lights.lamps_along_ray(origin, wi, t_lo, t_hi, s.pdf, true, sp.position);
            if (!lamps.is_black())
                out += dual_multiple_f_cos(dual, theta_i, theta_o, forward, sample_depth(forward.strands),
                                           v.bounces_left) *
                       lamps * inv_pdf;
            if (k < work.table.size()) add_crossing(forward, scene, work.table[k], wi, dual);
            t_lo = t_hi;
        }
        Rgb arriving;  // from beyond the strands: none past the cut
        if (!over && !mesh) {
            arriving = lights.escaped(sp.position, wi, s.pdf, true, true);
        } else if (!over && mesh->prim.geometry != PrimRef::kNone) {
            const SurfacePoint hit = scene.surface_point(origin, wi, *mesh);
            const Rgb emission = material_emission(scene.materials()[hit.material]);
            if (!emission.is_black()) {
                const float w = hit.is_light
                                    ? power_heuristic(s.pdf, lights.emissive_triangle_pdf(
                                                                 mesh->t, std::fabs(dot(hit.normal, wi))))
                                    : 1.0f;
                arriving = emission * w;
            }
        }
        if (!arriving.is_black())
            out += dual_multiple_f_cos(dual, theta_i, theta_o, forward, sample_depth(forward.strands),
                                       v.bounces_left) *
                   arriving * inv_pdf;
    }
    return out;
}

}  // namespace hairis
