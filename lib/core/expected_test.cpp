#include "core/expected.h"

#include <gtest/gtest.h>

#include <limits>

namespace hairis {
namespace {

TEST(Expected, HoldsValueOrError) {
    Expected<int> good = 3;
    ASSERT_TRUE(good.ok());
    EXPECT_EQ(good.value(), 3);
    Expected<int> bad = Error{"ior must be greater than 1"};
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().message, "ior must be greater than 1");
}

TEST(Check, MessagesNameTheParameterAndRange) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const Status f = check::finite("roughness", nan);
    ASSERT_TRUE(f);
    EXPECT_NE(f->message.find("roughness"), std::string::npos);
    const Status r = check::in_range("coat", 1.5, 0.0, 1.0);
    ASSERT_TRUE(r);
    EXPECT_NE(r->message.find("coat must be in [0, 1] (got 1.5)"), std::string::npos) << r->message;
    EXPECT_TRUE(check::in_range("coat", nan, 0.0, 1.0));
    EXPECT_FALSE(check::in_range("coat", 1.0, 0.0, 1.0));
    EXPECT_TRUE(check::greater_than("ior", 1.0, 1.0));
    EXPECT_FALSE(check::greater_than("ior", 1.55, 1.0));
    EXPECT_TRUE(check::non_negative("sigma_a.r", -0.1));
    EXPECT_TRUE(check::count_in_range("theta_i_count", 0, 1, 4096));
}

TEST(Check, FirstErrorKeepsOrder) {
    const Status s = first_error(check::finite("a", 1.0), check::in_range("b", 5, 0, 1),
                                 check::in_range("c", 5, 0, 1));
    ASSERT_TRUE(s);
    EXPECT_EQ(s->message.rfind("b ", 0), 0u) << s->message;
    EXPECT_FALSE(first_error(check::finite("a", 1.0)));
}

}  // namespace
}  // namespace hairis
