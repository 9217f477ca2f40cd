#include "render/dual_scattering_integrator.h"

#include "render/bsdf.h"
#include "render/path_integrator.h"
#include "render/sample_dims.h"

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

int StrandsBehind::cut(const Scene &scene, int strands, int bounces_left,
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
    work.strands_behind = behind(probe ? probe->wi : uniform_sphere(u.probe_u, u.probe_v));
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
                StrandsBehind &light_behind = crossings == &work.probe ? work.strands_behind : along_light;
                const int light_depth =
                    light_behind.cut(scene, forward.strands, v.bounces_left, work.behind, work.rays);
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
            return table_behind.cut(scene, strands, v.bounces_left, work.behind, work.rays);
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

DualScatteringIntegrator::DualScatteringIntegrator(const Scene &scene, const RenderSettings &settings)
    : scene_(scene),
      settings_(settings),
      enabled_(settings.integrator == int(Integrator::DualScattering)),
      layer_(settings.dual_hair_volume == int(DualHairVolume::Layer)),
      exact_bounces_(settings.dual_exact_bounces) {}

bool DualScatteringIntegrator::trace_through_hair(PathState &path, const PathRay &ray, std::optional<Hit> &hit,
                                                  bool &through_hair) {
    // Light meshes reflect onto the hair vertex through n ≥ 1 strands is the dual estimate's
    // global term: T_f d_f (f_s^scatter + π d_b f_back^scatter) for the sampled direction, in
    // place of f_s (lamps, suns and the world beyond hair are M's). Past the strands the
    // mesh's bounces allow, nothing it reflects counts (hit unset).
    PathCounters &counters = *path.counters;
    std::vector<StrandCrossing> &strands = counters.dual.continuation;
    const int budget = bounces_after(from_.bounces_left, 1);
    hit = scene_.trace_through_hair_within(ray.origin, ray.dir, ray.tmin, ray.tmax, ray.skip, {}, budget, strands);
    ++counters.rays;
    if (hit && hit->prim.geometry == PrimRef::kNone) hit.reset();  // untraceable: as intersect()
    if (strands.empty()) return true;
    path.add_reached(scene_.lights().lamps_along_ray(ray.origin, ray.dir, ray.tmin, strands[0].t,
                                                     path.prev_bsdf_pdf, path.use_mis, ray.from));
    if (!hit) return false;
    const ForwardScattering forward =
        gather_forward_scattering(scene_, strands.data(), strands.size(), ray.dir, *from_.dual);
    // The mesh is a vertex of its own, after the strands: it must be one the path tracer
    // would shade.
    const int behind = from_.strands_behind.cut(scene_, forward.strands, budget, counters.dual.behind,
                                                counters.shadow_rays);
    const Rgb m = dual_multiple_f_cos(*from_.dual, theta_of(from_.frame, ray.dir), from_.theta_o, forward,
                                      behind, budget);
    path.beta = from_.beta * m / path.prev_bsdf_pdf;
    if (path.beta.is_black() || !finite(path.beta)) return false;
    through_hair = true;
    // The mesh's own bounces count the strands crossed, as the path tracer's would.
    if (from_.bounces_left >= 0) {
        const int crossed = int(strands.size());
        path.vertex += crossed;
        path.transmission_bounces += crossed;
        path.last_segment = path.last_segment || path.transmission_bounces > settings_.max_transmission_bounces;
    }
    return true;
}

bool DualScatteringIntegrator::add_mesh_light(PathState &path, Vec3 dir, bool through_hair) {
    if (!from_.dual || !layer_ || through_hair) return true;
    // What the mesh reflects also carries the local multiple term over the continuation's
    // density, Ā_b cut at the strands behind the vertex along this light's travel, −ω_i (the
    // mesh's emission is f_s's alone: emitters' M is the light and table samples'). The mesh
    // is a vertex of its own after the strands behind and back: the cut.
    const int budget = bounces_after(from_.bounces_left, 1);
    StrandsBehind behind_mesh{from_.behind_origin, -dir, from_.self, strands_behind_cap(budget)};
    const int behind = behind_mesh.cut(scene_, 0, budget, path.counters->dual.behind, path.counters->rays);
    const Rgb m = from_.dual->local_f_cos(theta_of(from_.frame, dir), from_.theta_o, behind);
    path.beta += from_.beta * m / path.prev_bsdf_pdf;
    return finite(path.beta);
}

bool DualScatteringIntegrator::closes_path(const Material &material, const Bsdf &bsdf, const PathState &path) {
    // render() refuses hair without dual-scattering data; render_sample() path-traces it.
    const auto *hair = enabled_ ? std::get_if<HairMaterial>(&material) : nullptr;
    const bool closes = hair && hair->dual && hair->multiple && bsdf.hair() && path.vertex >= exact_bounces_;
    closing_ = closes ? hair : nullptr;
    // The scattering events the path tracer would still add after the vertex.
    closing_bounces_left_ = closes && settings_.dual_bounce_limit == int(DualBounceLimit::Bounces)
                                ? std::max(0, std::min(settings_.max_bounces - path.vertex,
                                                       settings_.max_transmission_bounces - path.transmission_bounces))
                                : -1;
    return closes;
}

void DualScatteringIntegrator::add_light(PathState &path, const SurfacePoint &sp, const Bsdf &bsdf, Vec3 wo,
                                         const SobolSampleRng &rng) {
    DualVertex v;
    v.point = &sp;
    v.material = closing_;
    v.bsdf = bsdf.hair();
    v.frame = bsdf.frame();
    v.wo = wo;
    v.layer = layer_;
    v.bounces_left = closing_bounces_left_;
    DualWork &work = path.counters->dual;
    const std::uint64_t before = work.rays;
    path.add(path.beta * dual_scattering_light(scene_, v, dual_random(rng, path.vertex), work));
    path.counters->shadow_rays += work.rays - before;
}

bool DualScatteringIntegrator::sample_continuation(const PathState &path, const Bsdf &bsdf, Vec3 wo,
                                                   const SobolSampleRng &rng, float u0, float u1, float u2,
                                                   Vec3 &wi, Rgb &weight, float &pdf, bool &glossy) const {
    if (!layer_) return bsdf.sample(u0, u1, u2, wi, weight, pdf, glossy);
    // A layer's continuation also carries the light meshes send through strands, the multiple
    // term's: a one-sample mixture of the material's sampler and the vertex's multiple table
    // (DualVertex::layer; its light samples MIS against the same).
    const MultipleTable &table = *closing_->multiple;
    const int strand = path.counters->dual.last_strand_index;
    const Vec3 wo_local = bsdf.frame().to_local(wo);
    float sampler_pdf = 0.0f, table_pdf = 0.0f;
    Rgb f_cos;
    if (rng.get(dual_dim(path.vertex, kDimDualMixture)) < kDualMixture) {
        if (!bsdf.sample(u0, u1, u2, wi, weight, sampler_pdf, glossy)) return false;
        f_cos = weight * sampler_pdf;
        table_pdf = multiple_table_pdf(table, strand, bsdf.frame(), wo_local, wi);
    } else {
        const MultipleTableSample t = sample_multiple_table(table, strand, bsdf.frame(), wo_local, u0, u1, u2);
        if (!(t.pdf > 0.0f)) return false;
        wi = t.wi;
        table_pdf = t.pdf;
        f_cos = bsdf.eval(wi, sampler_pdf);
    }
    pdf = dual_mixture_pdf(sampler_pdf, table_pdf);
    if (!(pdf > 0.0f)) return false;
    weight = f_cos / pdf;
    return true;
}

void DualScatteringIntegrator::leave(const PathState &path, const SurfacePoint &sp, const Bsdf &bsdf, Vec3 wo,
                                     Vec3 wi) {
    from_.dual = closing_ ? closing_->dual.get() : nullptr;
    if (!closing_) return;
    from_.frame = bsdf.frame();
    from_.theta_o = theta_of(bsdf.frame(), wo);
    from_.strands_behind = path.counters->dual.strands_behind;
    from_.beta = path.beta;
    from_.behind_origin = sp.spawn_point(-wi);
    from_.self = sp.self;
    from_.bounces_left = closing_bounces_left_;
}

}  // namespace hairis
