// integrator=dual_scattering: the light a hair shading point receives, estimated with Zinke,
// Yuksel, Weber and Keyser 2008 ("Dual Scattering Approximation for Fast Multiple Scattering
// in Hair") in its ray-shooting form — shadow rays let hair through, and the forward-scattering
// transmittance T_f and spread σ_f² are gathered strand by strand along them (the paper's
// products and sums over the strands crossed, each strand at its own inclination) — instead of
// its deep-opacity-map form. The averages (ā_f, β̄_f², Ā_b, Δ̄_b, σ̄_b, N_p^G) are
// fiber/dual_scattering.h's; single scattering f_s is the material's Cycles-exact fiber.
//
// At a hair vertex x seen from ω_o, for light L from direction ω_i that crosses n strands
// k = 1..n before reaching x (meshes block it):
//   n = 0:  F·cos θ_i = f_s·cos θ_i  +  d_b f_back^direct cos θ_i              = D + M
//   n ≥ 1:  F·cos θ_i = T_f d_f (f_s^scatter + π d_b f_back^scatter) cos θ_i    =     M
//   T_f = d_f Π_k a(θ_k),  σ_f² = Σ_k β̄_f²(θ_k),  θ_k = asin(ω_i · tangent_k),
// a(θ) = ā_f(θ) + sin²θ ā_b(θ) (DualScattering::crossing_attenuation: the paper's ā_f, and the
// backward-scattered light that still travels along the fiber), with a and β̄_f² from each
// crossed strand's own material, and d_f, d_b, the backscatter
// terms and f^scatter from the shading point's. D is single scattering of unoccluded light, M
// the multiple-scattering term (the local d_b f_back^direct where the light is visible, the
// global term where it is not).
//
// Estimator per vertex (three strategies, two MIS pairs; each lamp's light is its own integrand,
// as in the path tracer):
//  - light sampling (LightSet::sample): one shadow ray that lets hair through gives n, T_f and
//    σ_f²; D is weighted by the power heuristic against the material's sampler (the direct
//    tables as in the path tracer) and M against the multiple table;
//  - multiple-table sampling: ω_i from the baked 1D multiple-scattering table (MultipleTable)
//    of the strand count n_h estimated below, at θ_o; a ray that lets hair through gathers n,
//    T_f and σ_f² up to each lamp it crosses and to the world or sun it escapes to, and M there
//    is weighted against light sampling (LightSet's MIS densities, and weight 1 for a world
//    that is not light-sampled — a constant world's multiple scattering comes from here alone);
//  - the material's sampler draws the path's continuation as in the path tracer and collects
//    D from the emitters it reaches unoccluded, MIS-weighted as there. It ends at hair: light
//    reaching x from another strand is M's. It goes on from meshes (light that meshes reflect
//    onto hair: single-scattered with Unbounded; with Layer, F = f_s + d_b f_back^direct where
//    no strand is in the way, Ā_b cut along that light's travel, and the global term through
//    strands).
// n_h estimate: the strands a probe ray crosses from x towards a point drawn from LightSet with
// random numbers of its own (towards a direction uniform on the sphere when there is no lamp),
// up to the first mesh (and at most r + 1 under the bounce limit below: light past r strands
// does not count); that count (at least 1) is rounded in log2 to the nearest strand count
// the table holds. The probe is independent of the estimator's samples, so the table's density
// is fixed given the probe and MIS stays unbiased; when the probe and the light sample draw the
// same delta light their shadow rays coincide and one is traced.
//
// The hair volume (RenderSettings::dual_hair_volume). The paper's series for Ā_b, Δ̄_b and σ̄_b
// sum light that goes on through ever more strands behind x and comes back: a semi-infinite
// volume (Unbounded). Real hair is a layer over a head, and light that passes it reaches the
// skin instead. Layer (the default) cuts Ā_b's two series at the strands behind x along the
// light's travel, up to the first mesh (DualScattering::backscatter_attenuation(θ, depth)): for
// each light or table sample that brings light from ω_i, a ray from x along −ω_i counts them
// (the probe's when the light sample drew the probe's delta light); for the continuation's
// global term, a second probe from x away from the probe's light point, traced only when a
// term needs it (StrandsBehind). Δ̄_b and σ̄_b, ratios
// of the same series, are kept. In exchange, the continuation lets hair through: where it reaches a mesh after
// n ≥ 1 strands, its weight is the global term of the sampled direction (T_f and σ_f² of the
// strands it crossed, the vertex's depth) over the sampler's density instead of f_s over it,
// and only light the mesh reflects counts (its emission, lamps crossed after the first strand
// and the world beyond hair are M's, above). On blonde hair over a diffuse head the unbounded
// series were too red and the cut series alone too dark, so both are kept together.
//
// Exact bounces (RenderSettings::dual_exact_bounces, N): the vertices of depth < N are
// path-traced as integrator=path traces them (their light from other strands is found by
// their continuation), and the first hair vertex at depth >= N is shaded as above and closes
// the path. N = 0 is the paper's dual scattering at the first hair hit. What the paper's
// straight-line T_f gets wrong in a thin layer (light crossing it on grazing paths mostly
// leaves it, instead of arriving) is then only the part of the light that scattered N times:
// so the bias falls with every exact bounce while the noise per sample stays below path
// tracing's.
//
// Bounce limit (RenderSettings::dual_bounce_limit). The paper's M adds every order of
// scattering; the path tracer, like Cycles, ends a path after Max Bounces (and Max
// Transmission Bounces) vertices. With Bounces (the default) the closing vertex at depth d
// adds only what the path tracer would reach with the r = bounces_left events after it: light
// that crossed n strands needs n (none for n > r), and the i-th term of Ā_b's series (through
// i strands behind and back) 2i more, so the series stop at (r − n)/2 strands behind; the
// continuation's mesh counts the strands it crossed as the path tracer's bounces. Rays that
// let hair through stop once they know of more strands than their light may cross
// (Scene::trace_through_hair_within). On light hair the orders past the limit are a large
// share, which is why the limit follows the path tracer's. None keeps the paper's every order.
//
// What dual scattering covers: light from lamps, suns, emissive triangles and the world that
// reaches hair directly or through other strands. What is still traced: everything that
// arrives at meshes (hair is opaque to their shadow rays, as in the path tracer, and the light
// hair sends them — the head under the hair — is what their continuation rays find at hair
// vertices, each shaded as above), and light meshes reflect onto hair (with Layer F as for a
// lamp: f_s + d_b f_back^direct where no strand is in the way, the global term through strands;
// with Unbounded single scattering where no strand is in the way). Not covered
// with Unbounded: light that meshes reflect and that then crosses strands before reaching x.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/frame.h"
#include "fiber/dual_scattering.h"
#include "core/rng.h"
#include "render/render_settings.h"
#include "render/scene.h"
#include "sampling/hair_bsdf.h"
#include "sampling/sampling_table.h"

namespace hairis {

class Bsdf;
struct PathRay;
struct PathState;

/// The forward scattering gathered along a ray: strands crossed, Π a(θ_k) and Σ β̄_f²(θ_k)
/// (T_f without d_f, and σ_f²).
struct ForwardScattering {
    int strands = 0;
    Rgb attenuation{1.0f};
    Rgb spread_variance{0.0f};
};

/// Gathers the crossings strands[0 .. count) of a ray along unit direction `dir` (towards the
/// light): each strand's a (crossing_attenuation) and β̄_f² at θ_k = asin(dir · tangent_k)
/// from its material's dual-scattering data (`fallback` for a material without one).
ForwardScattering gather_forward_scattering(const Scene &scene, const StrandCrossing *strands,
                                            std::size_t count, Vec3 dir,
                                            const DualScattering &fallback);

/// The strands a layer counts behind a point (DualHairVolume::Layer) at most: the cut series
/// differ from the unbounded ones by ā_f^(2·64) <= 0.9025^64 < 1.5e-3 of them (ā_f is clamped
/// to 0.95 there), and a ray that has found them stops.
constexpr int kMaxStrandsBehind = 64;

/// A budget of scattering events (DualVertex::bounces_left) after `events` of it are spent:
/// unlimited (−1) stays so, otherwise at least 0.
inline int bounces_after(int bounces_left, int events) {
    return bounces_left < 0 ? bounces_left : (bounces_left > events ? bounces_left - events : 0);
}

/// Where Ā_b's series stop for light that crossed `strands` strands when the path may add
/// `bounces_left` more scattering events (−1: unlimited): each strand behind costs two (there
/// and back), so at min(depth, (bounces_left − strands)/2) and at least 0 (depth < 0: the
/// series are otherwise unbounded).
int backscatter_depth(int depth, int strands, int bounces_left);

/// The most strands behind a vertex that any of its terms can use with `bounces_left` events
/// left: min(bounces_left/2, kMaxStrandsBehind), kMaxStrandsBehind when unlimited (−1); 0: none,
/// and no count is needed.
inline int strands_behind_cap(int bounces_left) {
    return bounces_left < 0 ? kMaxStrandsBehind : std::min(bounces_left / 2, kMaxStrandsBehind);
}

/// M·cos θ_i of light from θ_i (fiber frame of the shading point) that crossed `forward`:
/// the local term for 0 strands, the global term with T_f = d_f·attenuation otherwise.
/// `bounces_left` (DualVertex::bounces_left; −1: unlimited) leaves out the orders the path
/// tracer would not reach: 0 when the strands alone exceed it, Ā_b cut by backscatter_depth.
Rgb dual_multiple_f_cos(const DualScattering &dual, float theta_i, float theta_o,
                        const ForwardScattering &forward, int depth = -1, int bounces_left = -1);

/// The index into table.n_h_values() of the strand count nearest max(strands, 1) in log2
/// (ties to the smaller count).
int nearest_strand_index(const MultipleTable &table, int strands);

/// A direction drawn from a multiple-scattering table, in world space.
struct MultipleTableSample {
    Vec3 wi;                ///< unit, towards the light
    float sin_theta_i = 0;  ///< wi's sin θ_i in the fiber frame
    float pdf = 0;          ///< per steradian; 0 when nothing was drawn
};

/// ω_i from `table` (strand index `strand`) for the view with fiber-frame direction wo_local
/// in `frame`: θ_i from the table's row of θ_o, φ uniform around the fiber.
MultipleTableSample sample_multiple_table(const MultipleTable &table, int strand,
                                          const FiberFrame &frame, Vec3 wo_local, float u0,
                                          float u1, float u2);
/// The density (per steradian) with which sample_multiple_table draws the unit direction wi.
float multiple_table_pdf(const MultipleTable &table, int strand, const FiberFrame &frame,
                         Vec3 wo_local, Vec3 wi);

/// The random numbers of one dual-scattering vertex, in [0, 1).
struct DualRandom {
    float light_select = 0, light_u = 0, light_v = 0;  ///< the light sample
    float probe_select = 0, probe_u = 0, probe_v = 0;  ///< the n_h probe
    float table_u0 = 0, table_u1 = 0, table_u2 = 0;    ///< the multiple-table sample
};

/// A hair vertex as the estimator sees it.
struct DualVertex {
    const SurfacePoint *point = nullptr;
    const HairMaterial *material = nullptr;  ///< with dual and multiple set
    const HairBsdf *bsdf = nullptr;          ///< the material's fiber and sampler at this hit
    FiberFrame frame;                        ///< the fiber frame the BSDF was prepared in
    Vec3 wo;                                 ///< unit, towards the viewer
    /// DualHairVolume::Layer: Ā_b cut at the strands behind the vertex, and the continuation
    /// drawn from dual_mixture_pdf (D's light samples MIS against it); false: the paper's
    /// unbounded series and the material's sampler.
    bool layer = false;
    /// The scattering events the path tracer would still add after this vertex (Max Bounces
    /// and Max Transmission Bounces less those spent, DualBounceLimit::Bounces); −1: every
    /// order, as in the paper.
    int bounces_left = -1;
};

/// The strands behind a point along unit `dir` up to the first mesh, where a layer cuts Ā_b's
/// series (DualHairVolume::Layer), counted the first time a term needs them.
struct StrandsBehind {
    Vec3 origin, dir;             ///< the point's spawn point along dir, and dir
    PrimRef self;                 ///< the point's curve
    int cap = kMaxStrandsBehind;  ///< the count stops there (strands_behind_cap)
    bool layer = true;            ///< false: the unbounded series, nothing to count
    int counted = -1;             ///< the count once traced
    /// Where Ā_b's series stop (backscatter_depth's `depth`) for light that crossed `strands`
    /// strands with `bounces_left` events left: −1 outside a layer, 0 without a ray where those
    /// events allow no strand behind, else the count (traced into `scratch` the first time,
    /// adding 1 to `rays`).
    int cut(const Scene &scene, int strands, int bounces_left, std::vector<StrandCrossing> &scratch,
            std::uint64_t &rays);
};

/// Per-thread buffers and counts of the estimator.
struct DualWork {
    std::vector<StrandCrossing> light, probe, table, behind, continuation;
    /// The strands behind the last vertex away from its probe's light point (the second probe):
    /// Ā_b's cut for the continuation's global term.
    StrandsBehind strands_behind;
    std::uint64_t rays = 0;       ///< rays traced (probe, light, table)
    int last_probe_strands = -1;  ///< the strands the last vertex's probe crossed
    int last_strand_index = -1;   ///< the index into the table's n_h values it chose
};

/// The share of the material's sampler in a layer vertex's continuation (DualVertex::layer),
/// the rest the multiple table's, and the mixture's density.
constexpr float kDualMixture = 0.5f;
inline float dual_mixture_pdf(float pdf_bsdf, float pdf_table) {
    return kDualMixture * pdf_bsdf + (1.0f - kDualMixture) * pdf_table;
}

/// The radiance the vertex sends towards ω_o from emitters by dual scattering (light and
/// multiple-table samples, MIS-weighted as described above; the continuation's share is the
/// caller's). Adds the rays it traces to work.rays.
Rgb dual_scattering_light(const Scene &scene, const DualVertex &vertex, const DualRandom &u,
                          DualWork &work);


/// What a dual vertex leaves for its continuation ray (DualScatteringIntegrator).
struct DualContinuation {
    const DualScattering *dual = nullptr;  ///< set while the ray comes from a dual vertex
    FiberFrame frame;                      ///< the vertex's fiber frame
    float theta_o = 0;                     ///< its view's θ
    StrandsBehind strands_behind;          ///< Ā_b's cut for the global term (DualWork::strands_behind)
    Rgb beta;                              ///< the path's throughput at the vertex
    Vec3 behind_origin;                    ///< the vertex's spawn point along −ω_i (ω_i: the continuation)
    PrimRef self;                          ///< the vertex's curve
    int bounces_left = -1;                 ///< DualVertex::bounces_left
};

/// integrator=dual_scattering inside one camera sample's path (PathIntegrator::li): which hair
/// vertex closes the path, that vertex's light estimate and continuation, and what the
/// continuation reaches (a mesh seen directly, which adds the local multiple term with Layer,
/// or through strands, whose weight is the global term). With integrator=path every hook does
/// nothing. The path calls, per vertex:
///  - traces_through_hair / trace_through_hair: the ray a Layer vertex left lets hair through;
///  - ends_at: hair that ray reaches ends the path (hair-to-hair light is the estimate's);
///  - add_mesh_light: the mesh term of light a mesh reflects onto the vertex;
///  - closes_path: whether this vertex is the dual one, then add_light (in place of
///    next-event estimation) and sample_continuation (in place of the BSDF sample);
///  - leave: at every vertex once its continuation is drawn.
class DualScatteringIntegrator {
  public:
    DualScatteringIntegrator(const Scene &scene, const RenderSettings &settings);

    /// Whether a hair vertex at `vertex` may be the dual one (past the exact bounces).
    bool may_shade(int vertex) const { return enabled_ && vertex >= exact_bounces_; }

    /// Whether the ray comes from a Layer vertex: trace it with trace_through_hair.
    bool traces_through_hair() const { return from_.dual && layer_; }
    /// Traces the continuation of a Layer vertex through hair to the first mesh within the
    /// strands its bounces allow (`hit`, unset past them). Where it crossed strands, it adds the
    /// lamps before the first one, takes the global term as the path's throughput and counts the
    /// strands as bounces (`through_hair`). False: the path ends.
    bool trace_through_hair(PathState &path, const PathRay &ray, std::optional<Hit> &hit,
                            bool &through_hair);

    /// Whether the hit ends the path: hair reached from a dual vertex.
    bool ends_at(const SurfacePoint &sp) const { return from_.dual && sp.is_curve; }

    /// A mesh a Layer vertex sees along `dir` with no strand in the way sends it light as a
    /// lamp does, F = f_s + d_b f_back^direct: adds the local multiple term over the
    /// continuation's density to the throughput. False: the throughput is not finite.
    bool add_mesh_light(PathState &path, Vec3 dir, bool through_hair);

    /// Whether the vertex of `material` with `bsdf` closes the path (a hair vertex with
    /// dual-scattering data past the exact bounces); remembered for the hooks below.
    bool closes_path(const Material &material, const Bsdf &bsdf, const PathState &path);
    /// The closing vertex's light by dual scattering (dual_scattering_light), added to the path.
    void add_light(PathState &path, const SurfacePoint &sp, const Bsdf &bsdf, Vec3 wo,
                   const SobolSampleRng &rng);
    /// The closing vertex's continuation from (u0, u1, u2): with Layer a one-sample mixture of
    /// the material's sampler and the vertex's multiple table (dual_mixture_pdf), otherwise the
    /// BSDF's sample. As Bsdf::sample.
    bool sample_continuation(const PathState &path, const Bsdf &bsdf, Vec3 wo, const SobolSampleRng &rng,
                             float u0, float u1, float u2, Vec3 &wi, Rgb &weight, float &pdf,
                             bool &glossy) const;
    /// The path leaves the vertex along `wi`: what its continuation needs, if it closes the path.
    void leave(const PathState &path, const SurfacePoint &sp, const Bsdf &bsdf, Vec3 wo, Vec3 wi);

  private:
    const Scene &scene_;
    const RenderSettings &settings_;
    bool enabled_;      // integrator=dual_scattering
    bool layer_;        // DualHairVolume::Layer
    int exact_bounces_;
    const HairMaterial *closing_ = nullptr;  // the vertex's material when it closes the path
    int closing_bounces_left_ = -1;          // its DualVertex::bounces_left
    DualContinuation from_;
};

}  // namespace hairis
