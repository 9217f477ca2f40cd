// The random-number dimensions of one camera sample, declared here alone: every number a path
// draws from its SobolSampleRng (core/rng.h) comes from a dimension named below, so that no two
// uses share one.
//
//   0, 1                         the pixel jitter
//   2 + 8·v + VertexDim          path vertex v (the camera's hit is v = 0): roulette, light
//                                sample, BSDF sample
//   2^24 + 8·v + DualDim         integrator=dual_scattering's extra numbers at vertex v
//
// SobolSampleRng stratifies dimensions 2k and 2k + 1 together, so the layout keeps the pairs
// that belong together: jitter (0, 1), light position (4, 5) and BSDF φ and θ (6, 7) of a vertex;
// probe point (0, 1), table θ_i and φ (2, 3), probe light and table node (4, 5) of the dual block.
#pragma once

#include <cstdint>

#include "core/rng.h"

namespace hairis {

struct DualRandom;

constexpr std::uint32_t kDimJitterU = 0, kDimJitterV = 1;
constexpr std::uint32_t kDimFirstVertex = 2;
constexpr std::uint32_t kDimsPerVertex = 8;

/// A path vertex's numbers, within its block of kDimsPerVertex.
enum VertexDim : std::uint32_t {
    kDimRoulette = 0,
    kDimLightSelect = 1,
    kDimLightU = 2,
    kDimLightV = 3,
    kDimBsdf0 = 4,
    kDimBsdf1 = 5,
    kDimBsdf2 = 6,
};
constexpr VertexDim kVertexDims[] = {kDimRoulette, kDimLightSelect, kDimLightU, kDimLightV,
                                     kDimBsdf0,    kDimBsdf1,       kDimBsdf2};

/// The dimension of number `d` of path vertex `vertex`.
constexpr std::uint32_t dim(int vertex, VertexDim d) {
    return kDimFirstVertex + std::uint32_t(vertex) * kDimsPerVertex + std::uint32_t(d);
}

/// The most vertices a path can have (Max Bounces is at most 1024, and the vertex after the
/// last shaded one only collects emission): the path's block ends below dim(kMaxPathVertices, 0).
constexpr int kMaxPathVertices = 1026;

/// Dual scattering's numbers live in a block of their own far above the path's, so that
/// integrator=path draws what it always drew.
constexpr std::uint32_t kDimDualFirst = 1u << 24;

/// A dual-scattering vertex's numbers, within its block of kDimsPerVertex.
enum DualDim : std::uint32_t {
    kDimProbeU = 0,
    kDimProbeV = 1,
    kDimTableU0 = 2,
    kDimTableU1 = 3,
    kDimProbeSelect = 4,
    kDimTableU2 = 5,
    /// A layer vertex's choice between the material's sampler and the multiple table for its
    /// continuation (kDualMixture).
    kDimDualMixture = 6,
};
constexpr DualDim kDualDims[] = {kDimProbeU,      kDimProbeV,  kDimTableU0,    kDimTableU1,
                                 kDimProbeSelect, kDimTableU2, kDimDualMixture};

/// The dimension of dual-scattering number `d` of vertex `vertex`.
constexpr std::uint32_t dual_dim(int vertex, DualDim d) {
    return kDimDualFirst + std::uint32_t(vertex) * kDimsPerVertex + std::uint32_t(d);
}

static_assert(sizeof(kVertexDims) / sizeof(kVertexDims[0]) <= kDimsPerVertex, "a vertex's numbers fit its block");
static_assert(sizeof(kDualDims) / sizeof(kDualDims[0]) <= kDimsPerVertex, "a dual vertex's numbers fit its block");
static_assert(dim(kMaxPathVertices, kDimRoulette) <= kDimDualFirst, "the dual block starts above every path's");

/// The numbers of the dual-scattering vertex `vertex`: the path's light sample (the estimate
/// replaces the path's next-event estimation) and the dual block's probe and table sample.
DualRandom dual_random(const SobolSampleRng &rng, int vertex);

/// The seed of the random numbers of the point at path vertex `vertex` (Huang's eval): from
/// the sample's key, not a Sobol dimension.
std::uint32_t vertex_seed(const SampleRng &key, int vertex);

}  // namespace hairis
