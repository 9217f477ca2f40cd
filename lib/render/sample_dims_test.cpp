#include "render/sample_dims.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <algorithm>
#include <map>
#include <string>

namespace hairis {
namespace {

TEST(SampleDims, NoTwoNamedDimensionsCollide) {
    // Every dimension a path of up to kMaxPathVertices vertices can draw, with who draws it.
    std::map<std::uint32_t, std::string> owner;
    auto claim = [&](std::uint32_t d, const std::string &who) {
        const auto [it, inserted] = owner.emplace(d, who);
        EXPECT_TRUE(inserted) << "dimension " << d << ": " << who << " and " << it->second;
    };
    claim(kDimJitterU, "jitter u");
    claim(kDimJitterV, "jitter v");
    for (int v = 0; v < kMaxPathVertices; ++v) {
        for (VertexDim d : kVertexDims) claim(dim(v, d), "vertex " + std::to_string(v) + " #" + std::to_string(d));
        for (DualDim d : kDualDims) claim(dual_dim(v, d), "dual " + std::to_string(v) + " #" + std::to_string(d));
    }
}

TEST(SampleDims, DualBlockLiesAbovePathBlock) {
    std::uint32_t path_max = kDimJitterV, dual_min = UINT32_MAX;
    for (int v = 0; v <= 1025; ++v) {
        for (VertexDim d : kVertexDims) path_max = std::max(path_max, dim(v, d));
        for (DualDim d : kDualDims) dual_min = std::min(dual_min, dual_dim(v, d));
    }
    EXPECT_LT(path_max, dual_min);
    EXPECT_EQ(dual_min, kDimDualFirst);
}

TEST(SampleDims, PairsThatBelongTogetherShareAStratum) {
    // SobolSampleRng stratifies 2k and 2k + 1 together.
    auto paired = [](std::uint32_t a, std::uint32_t b) { return a % 2 == 0 && b == a + 1; };
    EXPECT_TRUE(paired(kDimJitterU, kDimJitterV));
    for (int v : {0, 1, 7, 1024}) {
        EXPECT_TRUE(paired(dim(v, kDimLightU), dim(v, kDimLightV))) << v;
        EXPECT_TRUE(paired(dim(v, kDimBsdf0), dim(v, kDimBsdf1))) << v;
        EXPECT_TRUE(paired(dual_dim(v, kDimProbeU), dual_dim(v, kDimProbeV))) << v;
        EXPECT_TRUE(paired(dual_dim(v, kDimTableU0), dual_dim(v, kDimTableU1))) << v;
    }
}

TEST(SampleDims, VertexSeedsDiffer) {
    const SampleRng key(3, 17, 5);
    EXPECT_NE(vertex_seed(key, 0), vertex_seed(key, 1));
    EXPECT_NE(vertex_seed(key, 0), vertex_seed(SampleRng(3, 17, 6), 0));
}

}  // namespace
}  // namespace hairis
