#include "render/sample_dims.h"

#include "render/dual_scattering_integrator.h"

namespace hairis {

DualRandom dual_random(const SobolSampleRng &rng, int vertex) {
    DualRandom u;
    u.light_select = rng.get(dim(vertex, kDimLightSelect));
    u.light_u = rng.get(dim(vertex, kDimLightU));
    u.light_v = rng.get(dim(vertex, kDimLightV));
    u.probe_u = rng.get(dual_dim(vertex, kDimProbeU));
    u.probe_v = rng.get(dual_dim(vertex, kDimProbeV));
    u.table_u0 = rng.get(dual_dim(vertex, kDimTableU0));
    u.table_u1 = rng.get(dual_dim(vertex, kDimTableU1));
    u.probe_select = rng.get(dual_dim(vertex, kDimProbeSelect));
    u.table_u2 = rng.get(dual_dim(vertex, kDimTableU2));
    return u;
}

std::uint32_t vertex_seed(const SampleRng &key, int vertex) {
    return std::uint32_t(mix64(key.key() ^ (std::uint64_t(vertex + 1) * 0xd1b54a32d192ed03ull)) >> 32);
}

}  // namespace hairis
