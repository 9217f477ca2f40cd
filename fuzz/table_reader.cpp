// Fuzz target: table files from bytes in memory. The bytes go to decode_table_exr (the core
// reader) and to hairis_tables_load_memory (the C API, which also builds the samplers); a
// table that loads is then sampled, so whatever the reader accepts must be usable.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_input.h"
#include "hairis/hairis.h"
#include "tables/table_file.h"

namespace {

void sample_tables(const hairis_tables *tables) {
    hairis_sampler *sampler = hairis_sampler_create(nullptr, tables, "strategy=table;multiple_weight=0.25;n_h=1");
    if (!sampler) {
        hairis::fuzz::check_last_error("hairis_sampler_create");
        return;
    }
    // A few outgoing directions over the θ range, incl. along the fiber (θ = ±π/2).
    constexpr size_t n = 5;
    float wo[3 * n], u[3 * n], h[n], wi[3 * n], pdf[n], pdf2[n];
    const float theta[n] = {-1.5707964f, -0.7f, 0.0f, 0.9f, 1.5707964f};
    for (size_t k = 0; k < n; ++k) {
        wo[3 * k] = std::sin(theta[k]);
        wo[3 * k + 1] = std::cos(theta[k]);
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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    // The core reader: an error is fine, an accepted set must validate.
    hairis::Expected<hairis::TableSet> set = hairis::decode_table_exr(data, size);
    if (set && set.value().validate()) {
        std::fprintf(stderr, "decode_table_exr accepted a set that does not validate\n");
        std::abort();
    }

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
