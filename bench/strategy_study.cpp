// Strategies side by side in one run: relative variance per sample of the luminance estimate
// of ∫ f cos dω_i (the fiber's directional albedo, unit incident radiance) and the time per
// sample+pdf, for the Cycles-default Principled Hair fiber and its default tables.
//
//   Y = luminance(f_cos_near(ω_i, ω_o, h)) / pdf(ω_i | ω_o, h),  ω_i ~ pdf,  h ~ U[−1, 1]
//   relative variance per sample = Var[Y] / E[Y]²
//
// Usage: strategy_study [samples per θ_r, default 1000000]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <random>

#include "hairis/frame.h"
#include "study_common.h"

using namespace hairis;

int main(int argc, char **argv) {
    const long long n = argc > 1 ? std::atoll(argv[1]) : 1000000;
    const bench::StudySetup setup = bench::make_setup();
    const std::vector<bench::NamedSampler> samplers = bench::all_samplers(setup);
    const double theta_r_deg[] = {-80, -45, 0, 45, 80};

    // Two integrands: the near field at the sampled h (what a renderer evaluates, Cycles'
    // f) and the far field averaged over h (what the tables tabulate).
    for (int far = 0; far < 2; ++far) {
    const long long count = far ? std::max(1LL, n / 10) : n;
    std::printf("%s## Relative variance per sample of the albedo estimate, %s (Cycles-default fiber, %lld samples)\n\n",
                far ? "\n" : "", far ? "far-field f (averaged over h)" : "near-field f at h ~ U[-1, 1]", count);
    std::printf("| strategy |");
    for (double t : theta_r_deg) std::printf(" θ_r = %g° |", t);
    std::printf(" median |\n|---|");
    for (size_t k = 0; k < 6; ++k) std::printf("---|");
    std::printf("\n");
    for (size_t s = 0; s < samplers.size(); ++s) {
        std::printf("| %s |", samplers[s].name.c_str());
        std::vector<double> variances;
        for (double t : theta_r_deg) {
            const Vec3 wo = direction_of(float(radians(t)), -float(kHalfPi));
            std::mt19937_64 rng(1234);
            std::uniform_real_distribution<float> u(0.0f, 1.0f);
            double sum = 0, sum_sq = 0;
            for (long long k = 0; k < count; ++k) {
                const float h = 2.0f * u(rng) - 1.0f;
                const auto smp = samplers[s].sampler->sample(wo, h, u(rng), u(rng), u(rng));
                double y = 0;
                if (smp && smp->pdf > 0) {
                    const Rgb f = far ? setup.fiber->f_cos(smp->wi, wo) : setup.fiber->f_cos_near(smp->wi, wo, h);
                    y = double(luminance(f)) / double(smp->pdf);
                }
                sum += y;
                sum_sq += y * y;
            }
            const double mean = sum / double(count), var = sum_sq / double(count) - mean * mean;
            variances.push_back(var / (mean * mean));
            std::printf(" %.4g |", variances.back());
        }
        std::sort(variances.begin(), variances.end());
        std::printf(" %.4g |\n", variances[variances.size() / 2]);
    }
    }

    std::printf("\n## Time per sample+pdf (one thread, θ_r uniform in [−90°, 90°], h uniform)\n\n");
    std::printf("| strategy | ns per sample+pdf | million per second |\n|---|---|---|\n");
    const int queries = 1 << 20;
    std::vector<Vec3> views(queries);
    std::vector<float> hs(queries), us(3 * size_t(queries));
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int k = 0; k < queries; ++k) {
        views[size_t(k)] = direction_of(float(kPi) * (u(rng) - 0.5f), -float(kHalfPi));
        hs[size_t(k)] = 2.0f * u(rng) - 1.0f;
        for (int d = 0; d < 3; ++d) us[3 * size_t(k) + size_t(d)] = u(rng);
    }
    for (const bench::NamedSampler &s : samplers) {
        double best = 1e30;
        float checksum = 0;
        for (int repeat = 0; repeat < 3; ++repeat) {
            const auto start = std::chrono::steady_clock::now();
            for (int k = 0; k < queries; ++k) {
                const size_t i = size_t(k);
                const auto smp = s.sampler->sample(views[i], hs[i], us[3 * i], us[3 * i + 1], us[3 * i + 2]);
                if (smp) checksum += s.sampler->pdf(smp->wi, views[i], hs[i]);
            }
            const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() / queries;
            best = std::min(best, ns);
        }
        std::printf("| %s | %.1f | %.1f |\n", s.name.c_str(), best, 1e3 / best);
        if (!(checksum >= 0)) std::printf("(checksum %g)\n", double(checksum));
    }
    return 0;
}
