#include "core/scratch.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <set>

namespace hairis {
namespace {

struct alignas(32) Wide {
    double value[4];
};

TEST(ScratchBuffer, ObjectsAreAlignedDistinctAndKeepTheirValuesAcrossGrowth) {
    ScratchBuffer scratch(64);  // small: forces new blocks
    std::vector<Wide *> made;
    for (int i = 0; i < 100; ++i) {
        Wide &w = scratch.make<Wide>();
        for (double &v : w.value) v = i;
        made.push_back(&w);
        scratch.make<char>('x');  // misaligns the next start
    }
    std::set<Wide *> distinct(made.begin(), made.end());
    EXPECT_EQ(distinct.size(), made.size());
    for (int i = 0; i < 100; ++i) {
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(made[std::size_t(i)]) % alignof(Wide), 0u);
        for (double v : made[std::size_t(i)]->value) EXPECT_EQ(v, i);
    }
}

TEST(ScratchBuffer, ResetReusesTheMemory) {
    ScratchBuffer scratch(256);
    int *first = &scratch.make<int>(1);
    scratch.reset();
    int *again = &scratch.make<int>(2);
    EXPECT_EQ(first, again);
    EXPECT_EQ(*again, 2);
    for (int i = 0; i < 1000; ++i) scratch.make<double>(i);  // grows
    scratch.reset();
    scratch.make<double>(0.0);
    for (int i = 0; i < 1000; ++i) scratch.make<double>(i);  // fits in the grown block now
}

}  // namespace
}  // namespace hairis
