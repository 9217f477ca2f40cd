// Fuzz target: table files from bytes in memory. The bytes go to decode_table_exr (the core
// reader) and to hairis_tables_load_memory (the C API, which also builds the samplers); a
// table that loads is then sampled, so whatever the reader accepts must be usable: through
// the C API without a fiber (the far part), and through the strategy policy with a Chiang
// fiber of the tables' parameters (the near part), as a renderer samples them.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "core/frame.h"
#include "core/scratch.h"
#include "fiber/fiber_spec.h"
#include "fuzz_input.h"
#include "hairis/hairis.h"
#include "sampling/strategy.h"
#include "tables/table_file.h"

namespace {

constexpr size_t kViews = 5;
// Outgoing directions over the θ range, incl. along the fiber (θ = ±π/2).
constexpr float kTheta[kViews] = {-1.5707964f, -0.7f, 0.0f, 0.9f, 1.5707964f};

void sample_tables(const hairis_tables *tables) {
    hairis_sampler *sampler = hairis_sampler_create(nullptr, tables, "strategy=table;multiple_weight=0.25;n_h=1");
    if (!sampler) {
        hairis::fuzz::check_last_error("hairis_sampler_create");
        return;
    }
    constexpr size_t n = kViews;
    float wo[3 * n], u[3 * n], h[n], wi[3 * n], pdf[n], pdf2[n];
    for (size_t k = 0; k < n; ++k) {
        wo[3 * k] = std::sin(kTheta[k]);
        wo[3 * k + 1] = std::cos(kTheta[k]);
        wo[3 * k + 2] = 0.0f;
        for (size_t c = 0; c < 3; ++c) u[3 * k + c] = float((k * 3 + c) % 7) / 7.0f;
        h[k] = -1.0f + 0.5f * float(k);
    }
    hairis::fuzz::check_not_internal(hairis_sample(sampler, n, wo, h, u, wi, pdf), "hairis_sample");
    hairis::fuzz::check_not_internal(hairis_pdf(sampler, n, wi, wo, h, pdf2), "hairis_pdf");
    for (size_t k = 0; k < n; ++k)
        if (!std::isfinite(pdf[k]) || pdf[k] < 0.0f || !std::isfinite(pdf2[k]) || pdf2[k] < 0.0f) {
            std::fprintf(stderr, "sampling loaded tables gave pdf %g / %g\n", pdf[k], pdf2[k]);
            std::abort();
        }
    hairis_sampler_destroy(sampler);
}

// The Chiang fiber whose parameters the tables record (the names chiang_parameters writes),
// or null when a name is not one of them or a value is out of range.
std::shared_ptr<const hairis::ChiangFiber> fiber_of(const hairis::TableSet &t) {
    if (t.model != "chiang2016") return nullptr;
    hairis::ChiangParams p;
    for (const auto &[name, value] : t.parameters) {
        const float v = float(value);
        if (name == "sigma_a.r") p.sigma_a.r = v;
        else if (name == "sigma_a.g") p.sigma_a.g = v;
        else if (name == "sigma_a.b") p.sigma_a.b = v;
        else if (name == "roughness") p.roughness = v;
        else if (name == "radial_roughness") p.radial_roughness = v;
        else if (name == "coat") p.coat = v;
        else if (name == "ior") p.ior = v;
        else if (name == "offset") p.offset = v;
        else if (name == "cycles" && value == 4.2) p.tilt = hairis::ChiangTilt::Outgoing;
        else return nullptr;
    }
    hairis::Expected<hairis::ChiangFiber> fiber = hairis::ChiangFiber::create(p);
    if (!fiber) return nullptr;
    return std::make_shared<const hairis::ChiangFiber>(std::move(fiber).value());
}

[[noreturn]] void finding(const char *what, const std::string &detail = {}) {
    std::fprintf(stderr, "%s%s%s\n", what, detail.empty() ? "" : ": ", detail.c_str());
    std::abort();
}

// TABLE with the fiber the tables were baked for: the near part is what it samples.
void sample_near_field(const hairis::TableSet &set) {
    using namespace hairis;
    const std::shared_ptr<const ChiangFiber> fiber = fiber_of(set);
    if (!fiber || set.n_h_values.empty()) return;
    Expected<SamplingTables> tables = SamplingTables::from(set);
    if (!tables) {
        if (tables.error().kind != ErrorKind::InvalidTable) finding("SamplingTables::from failed", tables.error().message);
        return;
    }
    StrategyInputs in;
    in.chiang = fiber;
    in.tables = &tables.value();
    in.multiple_weight = 0.25f;
    in.n_h = set.n_h_values.front();
    Expected<std::shared_ptr<const Sampler>> sampler = make_sampler(StrategyKind::Table, in);
    if (!sampler) {
        // Tables that validate, baked for this very fiber, and with a near part must sample.
        const bool own = canonical_parameters(chiang_parameters(fiber->params())) == tables.value().parameters;
        if (own && set.near_field) finding("make_sampler refused valid tables of their own fiber", sampler.error().message);
        return;
    }
    ScratchBuffer scratch;
    for (size_t k = 0; k < kViews; ++k)
        for (const float h : {-0.9f, 0.0f, 0.6f}) {
            scratch.reset();
            const FiberHit hit{direction_of(kTheta[k], -float(kHalfPi)), h};
            const FiberPoint *point = &fiber->prepare(hit, scratch);
            const SamplerPoint &at = sampler.value()->at(hit, point, scratch);
            for (int j = 0; j < 4; ++j) {
                const float u[3] = {float((k + 3 * j) % 7) / 7.0f, float(j) / 4.0f, float((5 * j + 1) % 9) / 9.0f};
                const std::optional<DirectionSample> s = at.sample(u[0], u[1], u[2]);
                if (!s) continue;
                // A sample's density is pdf() there.
                const float again = at.pdf(s->wi);
                if (!std::isfinite(s->pdf) || !(s->pdf > 0.0f) || !(std::fabs(again - s->pdf) <= 1e-4f * s->pdf))
                    finding("sampling the near part gave pdf", std::to_string(s->pdf) + " / " + std::to_string(again));
            }
            // The density over the sphere: 8 equal bands of sin θ_i (one θ_i cell of a coarse
            // table each, or more) × 6 azimuths.
            for (int i = 0; i < 8; ++i)
                for (int j = 0; j < 6; ++j) {
                    const float sin_theta = -0.99f + 1.98f * float(i) / 7.0f, phi = -3.0f + 1.2f * float(j);
                    const float p = at.pdf(direction_of(std::asin(sin_theta), phi));
                    if (!std::isfinite(p) || p < 0.0f) finding("the near part's pdf is", std::to_string(p));
                }
        }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    // The core reader: an error is fine, an accepted set must validate.
    hairis::Expected<hairis::TableSet> set = hairis::decode_table_exr(data, size);
    if (set && set.value().validate()) finding("decode_table_exr accepted a set that does not validate");
    if (set) sample_near_field(set.value());

    hairis_tables *tables = hairis_tables_load_memory(size ? data : nullptr, size);
    if (!tables) {
        hairis::fuzz::check_last_error("hairis_tables_load_memory");
        return 0;
    }
    if (!set) {
        std::fprintf(stderr, "the C API loaded what decode_table_exr refused: %s\n",
                     set.error().message.c_str());
        std::abort();
    }
    sample_tables(tables);
    hairis_tables_destroy(tables);
    return 0;
}
