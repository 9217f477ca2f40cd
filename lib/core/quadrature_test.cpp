#include "core/quadrature.h"

#include <gtest/gtest.h>

#include <cmath>

namespace hairis {
namespace {

// ∫_{-1}^{1} x^k dx = 2/(k + 1) for even k, 0 for odd: the n-point rule is exact to 2n − 1.
TEST(GaussLegendre, IsExactForPolynomialsUpToDegree2nMinus1) {
    for (int n = 1; n <= GaussLegendre::kMaxPoints; ++n) {
        const GaussLegendre &gl = GaussLegendre::rule(n);
        ASSERT_EQ(gl.nodes.size(), std::size_t(n));
        for (int k = 0; k <= 2 * n - 1; ++k) {
            const double exact = k % 2 == 0 ? 2.0 / (k + 1) : 0.0;
            EXPECT_NEAR(gl.integrate(-1.0, 1.0, [k](double x) { return std::pow(x, k); }), exact, 1e-13)
                << "n = " << n << ", degree " << k;
        }
        for (std::size_t i = 1; i < gl.nodes.size(); ++i) EXPECT_LT(gl.nodes[i - 1], gl.nodes[i]);
    }
}

// Degree 2n is not integrated exactly: the rule really has n points.
TEST(GaussLegendre, IsNotExactAtDegree2n) {
    for (int n = 1; n <= 8; ++n) {
        const double value = GaussLegendre::rule(n).integrate(-1.0, 1.0, [n](double x) { return std::pow(x, 2 * n); });
        EXPECT_GT(std::fabs(value - 2.0 / (2 * n + 1)), 1e-6) << n;
    }
}

TEST(QuadratureRule, CompositeRuleIntegratesASmoothFunctionOnAnInterval) {
    const QuadratureRule q = QuadratureRule::composite(0.0, 3.0, 5, 4);
    ASSERT_EQ(q.x.size(), 20u);
    double sum = 0;
    for (std::size_t i = 0; i < q.x.size(); ++i) sum += q.w[i] * std::exp(q.x[i]);
    EXPECT_NEAR(sum, std::exp(3.0) - 1.0, 1e-9);
}

}  // namespace
}  // namespace hairis
