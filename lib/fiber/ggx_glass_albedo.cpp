#include "fiber/ggx_glass_albedo.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/quadrature.h"
#include "fiber/fresnel.h"
#include "fiber/ggx.h"

namespace hairis {

namespace {

// Cycles' threshold below which a microfacet lobe is treated as a mirror (α² <= 2e-10).
constexpr double kSmoothAlphaSquared = 2e-10;
// Cycles treats a refraction with |η − 1| below this as specular.
constexpr double kSpecularIorDistance = 1e-4;

constexpr int kLast = GgxGlassAlbedo::kSize - 1;

// One linear interpolation axis of Cycles' lookup_table_read: index, next index, fraction.
struct Axis {
    int index, next;
    float t;
};

Axis axis(float coordinate) {
    const float x = std::clamp(coordinate, 0.0f, 1.0f) * float(kLast);
    const int index = std::min(int(x), kLast);
    return {index, std::min(index + 1, kLast), x - float(index)};
}

}  // namespace

namespace {

// The integrand of E at one visible normal h: the reflected part where the reflection leaves
// above the surface, the refracted part on either side (see the header).
double albedo_integrand(double alpha, Vec3d w, double mu, double eta, bool specular_refraction,
                        Vec3d h) {
    const double c = dot(w, h);
    const double f = fresnel_dielectric(std::fabs(c), eta);
    double value = 0.0;
    const Vec3d reflected = 2.0 * c * h - w;
    if (reflected.z > 0.0) value += f * ggx::shadowing_ratio(alpha, mu, reflected.z);
    Vec3d refracted;
    if (f < 1.0 && ggx::refract(w, h, eta, refracted)) {
        value += (1.0 - f) * (specular_refraction ? 1.0 : ggx::shadowing_ratio(alpha, mu, refracted.z));
    }
    return value;
}

// Roots in [lo, hi] of a continuous function, by a uniform scan and bisection.
template <typename F>
void add_roots(const F &event, double lo, double hi, int scan, std::vector<double> &roots) {
    double x0 = lo, e0 = event(lo);
    for (int i = 1; i <= scan; ++i) {
        const double x1 = lo + (hi - lo) * i / scan, e1 = event(x1);
        if ((e0 < 0.0) != (e1 < 0.0)) {
            double a = x0, b = x1, ea = e0;
            for (int it = 0; it < 60 && b - a > 1e-13; ++it) {
                const double mid = 0.5 * (a + b), em = event(mid);
                if ((em < 0.0) == (ea < 0.0)) { a = mid; ea = em; } else { b = mid; }
            }
            roots.push_back(0.5 * (a + b));
        }
        x0 = x1;
        e0 = e1;
    }
}

}  // namespace

double ggx_glass_directional_albedo(double alpha, double mu, double eta, int order) {
    if (alpha * alpha <= kSmoothAlphaSquared) return 1.0;
    const Vec3d n{0, 0, 1};
    const Vec3d w{std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu};
    const bool specular_refraction = std::fabs(eta - 1.0) < kSpecularIorDistance;
    const ggx::VisibleParametrization p(alpha, w, n);
    if (!p.valid()) return 0.0;
    // Along ψ the integrand jumps where the reflection crosses the horizon and has a
    // square-root kink at the critical angle (η < 1): integrate piecewise between those.
    const double tir_cos2 = eta < 1.0 ? 1.0 - eta * eta : -1.0;
    const int panels = (order + GaussLegendre::kMaxPoints - 1) / GaussLegendre::kMaxPoints;
    const QuadratureRule outer = QuadratureRule::composite(-kHalfPi, kHalfPi, panels, (order + panels - 1) / panels);
    const GaussLegendre &inner = GaussLegendre::rule(std::min(GaussLegendre::kMaxPoints, std::max(4, order / 2)));
    const int scan = std::max(8, order / 2);
    double sum = 0.0;
    std::vector<double> breaks;
    for (size_t i = 0; i < outer.x.size(); ++i) {
        const double beta = outer.x[i];
        breaks.assign({p.psi_min(), 0.5 * kPi});
        add_roots([&](double psi) {
                      const Vec3d h = p.normal(beta, psi);
                      return 2.0 * dot(w, h) * h.z - w.z;
                  },
                  p.psi_min(), 0.5 * kPi, scan, breaks);
        if (tir_cos2 > 0.0) {
            add_roots([&](double psi) {
                          const double c = dot(w, p.normal(beta, psi));
                          return c * c - tir_cos2;
                      },
                      p.psi_min(), 0.5 * kPi, scan, breaks);
        }
        std::sort(breaks.begin(), breaks.end());
        double line = 0.0;
        for (size_t b = 0; b + 1 < breaks.size(); ++b) {
            const double half = 0.5 * (breaks[b + 1] - breaks[b]);
            const double mid = 0.5 * (breaks[b + 1] + breaks[b]);
            if (!(half > 0.0)) continue;
            for (size_t j = 0; j < inner.nodes.size(); ++j) {
                const double psi = mid + half * inner.nodes[j];
                line += inner.weights[j] * half * p.density(beta, psi) *
                        albedo_integrand(alpha, w, mu, eta, specular_refraction, p.normal(beta, psi));
            }
        }
        sum += outer.w[i] * line;
    }
    return std::clamp(sum, 0.0, 1.0);
}

double GgxGlassAlbedo::node_roughness(int k) { return std::clamp(double(k) / kLast, 1e-4, 1.0); }
double GgxGlassAlbedo::node_cosine(int j) { return std::clamp(double(j) / kLast, 1e-4, 1.0); }
double GgxGlassAlbedo::node_ior(int i, bool inverse) {
    const double z = std::clamp(double(i) / kLast, 1e-4, 0.99);
    const double eta = (1.0 + z * z) / (1.0 - z * z);
    return inverse ? 1.0 / eta : eta;
}

GgxGlassAlbedo::GgxGlassAlbedo() {
    for (std::atomic<float> &value : nodes_) value.store(std::numeric_limits<float>::quiet_NaN());
}

const GgxGlassAlbedo &GgxGlassAlbedo::tables() {
    static const GgxGlassAlbedo instance;
    return instance;
}

float GgxGlassAlbedo::node(bool inverse, int i, int j, int k) const {
    std::atomic<float> &slot = nodes_[size_t((inverse ? kNodes : 0) + i * kSize * kSize + j * kSize + k)];
    float value = slot.load(std::memory_order_relaxed);
    if (std::isnan(value)) {
        const double r = node_roughness(k);
        value = float(ggx_glass_directional_albedo(r * r, node_cosine(j), node_ior(i, inverse)));
        slot.store(value, std::memory_order_relaxed);
    }
    return value;
}

GgxGlassAlbedo::Table GgxGlassAlbedo::table(bool inverse) const {
    Table result{};
    tbb::parallel_for(0, kSize, [&](int i) {
        for (int j = 0; j < kSize; ++j)
            for (int k = 0; k < kSize; ++k) result[size_t(i * kSize * kSize + j * kSize + k)] = node(inverse, i, j, k);
    });
    return result;
}

float GgxGlassAlbedo::lookup(float sqrt_alpha, float mu, float eta) const {
    const bool inverse = eta < 1.0f;
    const float z = std::sqrt(std::fabs((eta - 1.0f) / (eta + 1.0f)));
    const Axis ax = axis(sqrt_alpha), ay = axis(mu), az = axis(z);
    auto row = [&](int i, int j) {
        return (1.0f - ax.t) * node(inverse, i, j, ax.index) + ax.t * node(inverse, i, j, ax.next);
    };
    auto slice = [&](int i) { return (1.0f - ay.t) * row(i, ay.index) + ay.t * row(i, ay.next); };
    return (1.0f - az.t) * slice(az.index) + az.t * slice(az.next);
}

}  // namespace hairis
