#include "render/bsdf.h"

#include <gtest/gtest.h>

#include "fiber/chiang_strands.h"
#include "fiber/principled_hair.h"

namespace hairis {
namespace {

// The typed accessors the renderer and the bake pick a model's path by (in place of casts).
TEST(Bsdf, ModelsSayWhatTheyAre) {
    PrincipledHairNode node;
    const ChiangFiber chiang = ChiangFiber::create(to_chiang_params(node).value()).value();
    const HuangFiber huang = HuangFiber::create(HuangParams{}).value();
    const ChiangStrands strands = ChiangStrands::create(node).value();

    const FiberModel &chiang_model = chiang, &huang_model = huang;
    const ShadingModel &chiang_shading = chiang, &huang_shading = huang, &strands_shading = strands;
    EXPECT_EQ(chiang_model.as_chiang(), &chiang);
    EXPECT_EQ(chiang_model.as_huang(), nullptr);
    EXPECT_EQ(huang_model.as_huang(), &huang);
    EXPECT_EQ(huang_model.as_chiang(), nullptr);
    EXPECT_EQ(huang_shading.as_huang(), &huang);
    EXPECT_EQ(chiang_shading.as_huang(), nullptr);
    EXPECT_EQ(strands_shading.as_huang(), nullptr);
    EXPECT_EQ(strands_shading.strand_inputs(), static_cast<const StrandInputReader *>(&strands));
    EXPECT_EQ(chiang_shading.strand_inputs(), nullptr);
    EXPECT_EQ(huang_shading.strand_inputs(), nullptr);
}

}  // namespace
}  // namespace hairis
