#include "fiber/ggx_glass_albedo.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/vec3d.h"
#include "fiber/fresnel.h"
#include "fiber/ggx.h"

namespace hairis {
namespace {

// E by Monte Carlo with Cycles' own recipe (cycles_precompute's "ggx_glass_E"): a visible
// normal from Cycles' sampler, reflection with probability F else refraction, weight G2/G1,
// a reflection below the surface counting 0. Independent of the table's quadrature (another
// algorithm over another parametrization); each weight is in [0, 1], so the standard error
// is at most 0.5/sqrt(n).
double monte_carlo_albedo(double alpha, double mu, double eta, int n, std::mt19937 &rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Vec3d normal{0, 0, 1}, w{std::sqrt(1.0 - mu * mu), 0.0, mu};
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const Vec3d h = ggx::sample_visible(alpha, w, normal, u(rng), u(rng));
        const double c = dot(w, h);
        if (!(c > 0.0)) continue;
        const double f = fresnel_dielectric(c, eta);
        Vec3d o;
        if (u(rng) < f) {
            o = 2.0 * c * h - w;
            if (!(o.z > 0.0)) continue;
        } else if (!ggx::refract(w, h, eta, o)) {
            continue;
        }
        sum += ggx::shadowing_ratio(alpha, mu, o.z);
    }
    return sum / n;
}

TEST(GgxGlassAlbedo, NodesMatchMonteCarloIntegral) {
    // Nodes across roughness, incidence and both tables, grazing included. Tolerance: 4
    // standard errors of the Monte Carlo estimate (≤ 0.5/sqrt(n) = 1.1e-3) plus the table's
    // stated quadrature accuracy of 1e-3.
    const GgxGlassAlbedo &tables = GgxGlassAlbedo::tables();
    std::mt19937 rng(7);
    const int n = 200000;
    const int nodes[][4] = {{0, 5, 3, 4},  {0, 10, 1, 8}, {0, 15, 8, 15}, {0, 8, 15, 2},
                            {1, 5, 3, 4},  {1, 10, 1, 8}, {1, 15, 8, 15}, {1, 8, 15, 2},
                            {1, 6, 4, 12}, {0, 3, 12, 6}, {1, 12, 2, 3},  {0, 14, 6, 10}};
    for (const auto &node : nodes) {
        const bool inverse = node[0] == 1;
        const int i = node[1], j = node[2], k = node[3];
        const double r = GgxGlassAlbedo::node_roughness(k);
        const double reference = monte_carlo_albedo(r * r, GgxGlassAlbedo::node_cosine(j),
                                                    GgxGlassAlbedo::node_ior(i, inverse), n, rng);
        const double tolerance = 4.0 * 0.5 / std::sqrt(double(n)) + 1e-3;
        EXPECT_NEAR(tables.node(inverse, i, j, k), reference, tolerance)
            << (inverse ? "inverse " : "") << "node " << i << "," << j << "," << k;
    }
}

TEST(GgxGlassAlbedo, LookupInterpolatesTrilinearly) {
    const GgxGlassAlbedo &t = GgxGlassAlbedo::tables();
    // At a node the lookup is the node; between two roughness nodes it is their mean.
    const float eta = float(GgxGlassAlbedo::node_ior(6, false));
    EXPECT_NEAR(t.lookup(7.0f / 15.0f, 4.0f / 15.0f, eta), t.node(false, 6, 4, 7), 2e-5);
    EXPECT_NEAR(t.lookup(7.5f / 15.0f, 4.0f / 15.0f, eta), 0.5f * (t.node(false, 6, 4, 7) + t.node(false, 6, 4, 8)), 2e-5);
    // η < 1 reads the inverse table at the same Fresnel coordinate.
    EXPECT_NEAR(t.lookup(7.0f / 15.0f, 4.0f / 15.0f, 1.0f / eta), t.node(true, 6, 4, 7), 2e-5);
}

}  // namespace
}  // namespace hairis
