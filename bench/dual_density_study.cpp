// Dual scattering's mean error against the path tracer over the hair's density and thickness,
// its melanin and Exact Bounces, on bench/hair_ball.h's ball without Blender (64 × 64, 8
// bounces, Max Transmission Bounces 12, the Bounce Limit on): the mean of each channel over
// the hair pixels (alpha > 0.5 in a render of the strands alone), DUAL − PATH relative to
// PATH's, with the two seeds' spread of each as its standard error. Markdown to stdout.
//   dual_density_study [path spp per seed (128)] [dual spp per seed (32)]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "hair_ball.h"
#include "render/render.h"

namespace hairis::bench {
namespace {

constexpr int kSize = 64;

struct Means {
    double rgb[3] = {0, 0, 0};
};

// The mean of each channel over `mask`'s pixels of a render of `scene`.
Means render_means(const Scene &scene, RenderSettings s, const std::vector<bool> &mask) {
    std::vector<float> rgba(std::size_t(kSize) * kSize * 4);
    if (const Status status = render(scene, s, rgba.data(), {}, nullptr)) {
        std::fprintf(stderr, "render: %s\n", status->message.c_str());
        std::exit(1);
    }
    Means m;
    std::size_t n = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        if (!mask[i]) continue;
        ++n;
        for (int c = 0; c < 3; ++c) m.rgb[c] += rgba[4 * i + std::size_t(c)];
    }
    for (double &v : m.rgb) v /= double(std::max<std::size_t>(n, 1));
    return m;
}

RenderSettings settings(Integrator integrator, int spp, std::uint64_t seed, int exact) {
    RenderSettings s;
    s.integrator = int(integrator);
    s.samples = spp;
    s.seed = seed;
    s.max_bounces = 8;
    s.max_transmission_bounces = 12;
    s.threads = 0;
    s.dual_exact_bounces = exact;
    return s;
}

int run(int path_spp, int dual_spp) {
    std::printf("# Dual scattering's bias over hair density and thickness\n\n"
                "Made by `build/bench/dual_density_study %d %d`: bench/hair_ball.h's ball (strands "
                "rooted on a sphere of 0.98 m under a sun and a dim world, radius 4 mm at the root to "
                "1 mm at the tip times the thickness), 64 × 64, 8 bounces, Max Transmission Bounces 12, "
                "the Bounce Limit on. DUAL − PATH per channel over the hair pixels, relative to PATH's "
                "mean; PATH at %d spp and DUAL at %d spp, each two seeds (± from their spread).\n\n",
                path_spp, dual_spp, 2 * path_spp, 2 * dual_spp);
    std::printf("| strands | thickness | melanin | Exact Bounces | PATH mean (R, G, B) | DUAL − PATH (R, G, B) |\n"
                "| --- | --- | --- | --- | --- | --- |\n");
    for (const std::size_t strands : {12000, 40000})
        for (const float thickness : {1.0f, 3.0f})
            for (const float melanin : {0.1f, 0.5f}) {
                HairBall ball;
                ball.strands = strands;
                ball.thickness = thickness;
                ball.melanin = melanin;
                ball.size = kSize;
                // The hair pixels: alpha of the strands alone.
                ball.mesh = false;
                auto alone = hair_ball_scene(ball, StrategyKind::Analytic, false);
                ball.mesh = true;
                auto scene = hair_ball_scene(ball, StrategyKind::Table, true);
                if (!alone || !scene) {
                    std::fprintf(stderr, "scene: %s\n", (!alone ? alone : scene).error().message.c_str());
                    return 1;
                }
                RenderSettings a = settings(Integrator::Path, 16, 1, 0);
                a.film_transparent = true;
                a.max_bounces = 0;
                std::vector<float> rgba(std::size_t(kSize) * kSize * 4);
                if (const Status status = render(alone.value(), a, rgba.data(), {}, nullptr)) {
                    std::fprintf(stderr, "render: %s\n", status->message.c_str());
                    return 1;
                }
                std::vector<bool> mask(std::size_t(kSize) * kSize);
                for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = rgba[4 * i + 3] > 0.5f;

                const Means p1 = render_means(scene.value(), settings(Integrator::Path, path_spp, 1000, 3), mask);
                const Means p2 = render_means(scene.value(), settings(Integrator::Path, path_spp, 1001, 3), mask);
                for (const int exact : {3, 5}) {
                    const Means d1 = render_means(scene.value(), settings(Integrator::DualScattering, dual_spp, 1, exact), mask);
                    const Means d2 = render_means(scene.value(), settings(Integrator::DualScattering, dual_spp, 2, exact), mask);
                    std::string path, diff;
                    for (int c = 0; c < 3; ++c) {
                        const double p = 0.5 * (p1.rgb[c] + p2.rgb[c]), d = 0.5 * (d1.rgb[c] + d2.rgb[c]);
                        const double se = std::hypot(0.5 * (p1.rgb[c] - p2.rgb[c]), 0.5 * (d1.rgb[c] - d2.rgb[c]));
                        char buf[64];
                        std::snprintf(buf, sizeof buf, "%s%.4f", c ? ", " : "", p);
                        path += buf;
                        std::snprintf(buf, sizeof buf, "%s%+.1f ± %.1f%%", c ? ", " : "", 100.0 * (d / p - 1.0), 100.0 * se / p);
                        diff += buf;
                    }
                    std::printf("| %zu | %.0f | %.1f | %d | %s | %s |\n", strands, double(thickness), double(melanin),
                                exact, path.c_str(), diff.c_str());
                    std::fflush(stdout);
                }
            }
    return 0;
}

}  // namespace
}  // namespace hairis::bench

int main(int argc, char **argv) {
    const int path_spp = argc > 1 ? std::atoi(argv[1]) : 128;
    const int dual_spp = argc > 2 ? std::atoi(argv[2]) : 32;
    if (path_spp < 1 || dual_spp < 1) {
        std::fprintf(stderr, "usage: dual_density_study [path spp per seed >= 1] [dual spp per seed >= 1]\n");
        return 2;
    }
    return hairis::bench::run(path_spp, dual_spp);
}
