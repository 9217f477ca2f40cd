// Dual scattering's mean error against the path tracer over the hair's density, thickness and
// orientation, its melanin and Exact Bounces, on bench/common/hair_ball.h's ball without Blender
// (64 × 64, 8 bounces, Max Transmission Bounces 12, the Bounce Limit on): the mean of each
// channel over the hair pixels (alpha > 0.5 in a render of the strands alone), DUAL − PATH
// relative to PATH's, each over four seeds whose spread gives its standard error. Then, for
// one leaning and one straight blonde ball, every order: DUAL without the Bounce Limit against
// PATH at 64 bounces, which separates the closed form's error from the cut's, and at 4 bounces
// (Exact 3: the closing vertex's light crossed at most one strand), with and without the skin,
// and with the paper's density factor d_f at 0.8 instead of 0.7.
// Markdown to stdout.
//   dual_density_study [path spp (512)] [dual spp (128)] [all|leaning|straight]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "hair_ball.h"
#include "render/render.h"

namespace hairis::bench {
namespace {

constexpr int kSize = 64;

constexpr int kSeeds = 4;

struct Means {
    double rgb[3] = {0, 0, 0};
};

/// One render's means per seed (kSeeds seeds of spp / kSeeds samples each).
struct Runs {
    Means seed[kSeeds];
    double mean(int ch) const {
        double m = 0;
        for (const Means &r : seed) m += r.rgb[ch];
        return m / kSeeds;
    }
    /// The standard error of mean(ch), from the seeds' sample standard deviation.
    double standard_error(int ch) const {
        const double m = mean(ch);
        double ss = 0;
        for (const Means &r : seed) ss += (r.rgb[ch] - m) * (r.rgb[ch] - m);
        return std::sqrt(ss / (kSeeds - 1) / kSeeds);
    }
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

RenderSettings settings(Integrator integrator, int spp, int exact, int bounces = 8) {
    RenderSettings s;
    s.integrator = int(integrator);
    s.samples = spp;
    s.max_bounces = bounces;
    s.max_transmission_bounces = std::max(bounces, 12);
    s.threads = 0;
    s.dual_exact_bounces = exact;
    return s;
}

struct Case {
    std::size_t strands;
    bool straight;
    float thickness, melanin;
    bool every_order;  ///< the rows without the Bounce Limit against 64-bounce path tracing
};

// The hair pixels of `ball`: alpha of the strands alone.
Expected<std::vector<bool>> hair_mask(HairBall ball) {
    ball.mesh = false;
    auto alone = hair_ball_scene(ball, StrategyKind::Analytic, false);
    if (!alone) return alone.error();
    RenderSettings a = settings(Integrator::Path, 16, 0);
    a.film_transparent = true;
    a.max_bounces = 0;
    std::vector<float> rgba(std::size_t(kSize) * kSize * 4);
    if (const Status status = render(alone.value(), a, rgba.data(), {}, nullptr)) return *status;
    std::vector<bool> mask(std::size_t(kSize) * kSize);
    for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = rgba[4 * i + 3] > 0.5f;
    return mask;
}

// kSeeds renders of `scene` with `s` (its samples split over them, seeds first_seed + k).
Runs render_runs(const Scene &scene, RenderSettings s, const std::vector<bool> &mask, std::uint64_t first_seed) {
    Runs runs;
    s.samples = std::max(1, s.samples / kSeeds);
    for (int k = 0; k < kSeeds; ++k) {
        s.seed = first_seed + std::uint64_t(k);
        runs.seed[k] = render_means(scene, s, mask);
    }
    return runs;
}

// "P̄ (R, G, B)" and "D̄ − P̄ ± se" per channel.
void print_row(const Case &c, const char *what, const Runs &path_runs, const Runs &dual_runs) {
    std::string path, diff;
    for (int ch = 0; ch < 3; ++ch) {
        const double p = path_runs.mean(ch), d = dual_runs.mean(ch);
        const double se = std::hypot(path_runs.standard_error(ch), dual_runs.standard_error(ch));
        char buf[64];
        std::snprintf(buf, sizeof buf, "%s%.4f", ch ? ", " : "", p);
        path += buf;
        std::snprintf(buf, sizeof buf, "%s%+.1f ± %.1f%%", ch ? ", " : "", 100.0 * (d / p - 1.0), 100.0 * se / p);
        diff += buf;
    }
    std::printf("| %zu | %s | %.1f | %.1f | %s | %s | %s |\n", c.strands, c.straight ? "straight" : "leaning",
                double(c.thickness), double(c.melanin), what, path.c_str(), diff.c_str());
    std::fflush(stdout);
}

int run(int path_spp, int dual_spp, const std::string &which) {
    std::printf("# Dual scattering's bias over hair density, thickness and orientation\n\n"
                "Made by `build/bench/dual_density_study %d %d%s%s`: bench/common/hair_ball.h's ball (strands "
                "rooted on a sphere of 0.98 m under a sun and a dim world, radius 4 mm at the root to "
                "1 mm at the tip times the thickness; leaning at random, or straight along the normal as "
                "Blender's particle hair grows), 64 × 64, 8 bounces, Max Transmission Bounces 12, "
                "the Bounce Limit on. DUAL − PATH per channel over the hair pixels, relative to PATH's "
                "mean; PATH at %d spp and DUAL at %d spp, each over %d seeds (±: the standard error of the "
                "difference from the seeds' spread). "
                "*Every order*: DUAL without the Bounce Limit against PATH at 64 bounces (Max "
                "Transmission Bounces 64), the closed form's own error; *4 bounces*: the closing vertex has "
                "one event left, so its light is direct or crossed one strand (the global term at n = 1 "
                "alone), with the skin and without it; *d_f 0.8*: the paper's density factor d_f (0.7 "
                "everywhere else) at 0.8.\n\n",
                path_spp, dual_spp, which == "all" ? "" : " ", which == "all" ? "" : which.c_str(), path_spp,
                dual_spp, kSeeds);
    std::printf("| strands | strands grow | thickness | melanin | DUAL | PATH mean (R, G, B) | DUAL − PATH (R, G, B) |\n"
                "| --- | --- | --- | --- | --- | --- | --- |\n");
    std::vector<Case> cases;
    for (const std::size_t strands : {12000, 40000})
        for (const float thickness : {1.0f, 3.0f})
            for (const float melanin : {0.1f, 0.5f})
                cases.push_back({strands, false, thickness, melanin, strands == 12000 && thickness == 1.0f && melanin == 0.1f});
    // The demo head's particle hair: 15,000 strands straight along the normal, about 5× as thick.
    for (const float thickness : {1.0f, 2.5f, 5.0f}) cases.push_back({15000, true, thickness, 0.1f, thickness == 2.5f});
    cases.push_back({15000, true, 2.5f, 0.5f, false});
    cases.push_back({15000, false, 5.0f, 0.1f, false});
    for (const Case &c : cases) {
        if ((which == "leaning" && c.straight) || (which == "straight" && !c.straight)) continue;
        HairBall ball;
        ball.strands = c.strands;
        ball.straight = c.straight;
        ball.thickness = c.thickness;
        ball.melanin = c.melanin;
        ball.size = kSize;
        auto mask = hair_mask(ball);
        auto scene = hair_ball_scene(ball, StrategyKind::Table, true);
        if (!mask || !scene) {
            std::fprintf(stderr, "scene: %s\n", (!mask ? mask.error() : scene.error()).message.c_str());
            return 1;
        }
        const Runs path = render_runs(scene.value(), settings(Integrator::Path, path_spp, 3), mask.value(), 1000);
        for (const int exact : {3, 5}) {
            const std::string what = "Exact " + std::to_string(exact);
            print_row(c, what.c_str(), path,
                      render_runs(scene.value(), settings(Integrator::DualScattering, dual_spp, exact), mask.value(), 1));
        }
        if (!c.every_order) continue;
        // One event after the closing vertex: its light is direct or crossed one strand (the
        // global term at n = 1 alone), with and without the skin.
        for (const bool skin : {true, false}) {
            ball.mesh = skin;
            auto one = hair_ball_scene(ball, StrategyKind::Table, true);
            if (!one) {
                std::fprintf(stderr, "scene: %s\n", one.error().message.c_str());
                return 1;
            }
            print_row(c, skin ? "Exact 3, 4 bounces" : "Exact 3, 4 bounces, no skin",
                      render_runs(one.value(), settings(Integrator::Path, path_spp, 3, 4), mask.value(), 1000),
                      render_runs(one.value(), settings(Integrator::DualScattering, dual_spp, 3, 4), mask.value(), 1));
        }
        // The paper's density factor d_f (0.7) scales the global term by d_f²: 0.8 instead.
        {
            HairBall denser = ball;
            denser.mesh = true;
            denser.dual.d_f = 0.8f;
            auto other = hair_ball_scene(denser, StrategyKind::Table, true);
            if (!other) {
                std::fprintf(stderr, "scene: %s\n", other.error().message.c_str());
                return 1;
            }
            print_row(c, "Exact 3, d_f 0.8", path,
                      render_runs(other.value(), settings(Integrator::DualScattering, dual_spp, 3), mask.value(), 1));
        }
        const Runs path64 = render_runs(scene.value(), settings(Integrator::Path, path_spp, 3, 64), mask.value(), 1000);
        for (const int exact : {3, 5}) {
            RenderSettings d = settings(Integrator::DualScattering, dual_spp, exact, 64);
            d.dual_bounce_limit = int(DualBounceLimit::None);
            const std::string what = "Exact " + std::to_string(exact) + ", every order";
            print_row(c, what.c_str(), path64, render_runs(scene.value(), d, mask.value(), 1));
        }
    }
    return 0;
}

}  // namespace
}  // namespace hairis::bench

int main(int argc, char **argv) {
    const int path_spp = argc > 1 ? std::atoi(argv[1]) : 512;
    const int dual_spp = argc > 2 ? std::atoi(argv[2]) : 128;
    const std::string which = argc > 3 ? argv[3] : "all";
    using hairis::bench::kSeeds;
    if (path_spp < kSeeds || dual_spp < kSeeds || path_spp % kSeeds || dual_spp % kSeeds || argc > 4 || (which != "all" && which != "leaning" && which != "straight")) {
        std::fprintf(stderr,
                     "usage: dual_density_study [path spp] [dual spp] [all|leaning|straight]\n"
                     "  (spp: multiples of %d, split over that many seeds)\n",
                     kSeeds);
        return 2;
    }
    return hairis::bench::run(path_spp, dual_spp, which);
}
