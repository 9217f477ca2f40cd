#include "fiber/fresnel.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/math.h"

namespace hairis {
namespace {

const double kEtas[] = {1.1, 1.33, 1.55, 2.4};

// Textbook s- and p-reflectances for light going from index 1 into index eta at angle θ_i.
double reference_rs(double theta_i, double eta) {
    const double sin_t = std::sin(theta_i) / eta;
    const double cos_i = std::cos(theta_i), cos_t = std::sqrt(1.0 - sin_t * sin_t);
    return sqr((cos_i - eta * cos_t) / (cos_i + eta * cos_t));
}
double reference_rp(double theta_i, double eta) {
    const double sin_t = std::sin(theta_i) / eta;
    const double cos_i = std::cos(theta_i), cos_t = std::sqrt(1.0 - sin_t * sin_t);
    return sqr((cos_t - eta * cos_i) / (cos_t + eta * cos_i));
}

TEST(FresnelDielectric, NormalIncidenceMatchesClosedForm) {
    for (double eta : kEtas) {
        const double expected = sqr((eta - 1.0) / (eta + 1.0));
        EXPECT_NEAR(fresnel_dielectric(1.0, eta), expected, 1e-14) << eta;
        EXPECT_NEAR(fresnel_dielectric(1.0f, float(eta)), float(expected), 1e-7f) << eta;
        // From inside at normal incidence: the same reflectance.
        EXPECT_NEAR(fresnel_dielectric(-1.0, eta), expected, 1e-14) << eta;
    }
}

TEST(FresnelDielectric, MatchesTextbookFormulaAndBrewsterAngle) {
    for (double eta : kEtas) {
        for (int i = 0; i <= 80; ++i) {
            const double theta = radians(i);
            const double expected = 0.5 * (reference_rs(theta, eta) + reference_rp(theta, eta));
            EXPECT_NEAR(fresnel_dielectric(std::cos(theta), eta), expected, 1e-12)
                << eta << " " << i;
        }
        // At Brewster's angle atan(η) the p-reflectance vanishes and R_s = ((η²−1)/(η²+1))².
        const double brewster = std::atan(eta);
        EXPECT_NEAR(fresnel_dielectric(std::cos(brewster), eta),
                    0.5 * sqr((eta * eta - 1.0) / (eta * eta + 1.0)), 1e-12);
    }
}

TEST(FresnelDielectric, GrazingIncidenceReflectsEverything) {
    for (double eta : kEtas) {
        EXPECT_DOUBLE_EQ(fresnel_dielectric(0.0, eta), 1.0);
        EXPECT_FLOAT_EQ(fresnel_dielectric(0.0f, float(eta)), 1.0f);
        // Approaches 1 continuously and monotonically.
        double previous = fresnel_dielectric(1.0, eta);
        for (double c : {0.5, 0.1, 1e-2, 1e-3, 1e-5}) {
            const double r = fresnel_dielectric(c, eta);
            EXPECT_GT(r, previous) << c;
            EXPECT_LT(r, 1.0);
            previous = r;
        }
        EXPECT_GT(fresnel_dielectric(1e-6, eta), 1.0 - 1e-4);
    }
}

TEST(FresnelDielectric, TotalInternalReflectionFromInside) {
    for (double eta : kEtas) {
        const double critical = std::asin(1.0 / eta);
        // Light from inside (negative cosine) beyond the critical angle is fully reflected.
        EXPECT_DOUBLE_EQ(fresnel_dielectric(-std::cos(critical + 1e-3), eta), 1.0);
        EXPECT_DOUBLE_EQ(fresnel_dielectric(-std::cos(0.5 * (critical + kHalfPi)), eta), 1.0);
        EXPECT_FLOAT_EQ(fresnel_dielectric(-float(std::cos(critical + 1e-2)), float(eta)), 1.0f);
        // Just inside the critical angle it is not.
        EXPECT_LT(fresnel_dielectric(-std::cos(critical - 1e-2), eta), 1.0);
        // From outside there is never total reflection (short of grazing).
        EXPECT_LT(fresnel_dielectric(std::cos(critical + 1e-3), eta), 1.0);
    }
}

TEST(FresnelDielectric, StokesReciprocityInsideAndOutside) {
    // Stokes: r' = −r, so the reflectance at θ_i from outside equals the reflectance at the
    // refracted angle θ_t from inside, and 1 − R is the same transmittance both ways.
    for (double eta : kEtas) {
        for (int i = 0; i < 90; i += 3) {
            const double theta_i = radians(i);
            const double theta_t = std::asin(std::sin(theta_i) / eta);
            const double outside = fresnel_dielectric(std::cos(theta_i), eta);
            const double inside = fresnel_dielectric(-std::cos(theta_t), eta);
            EXPECT_NEAR(outside, inside, 1e-12) << eta << " " << i;
            // Equivalently: the inverse index with a positive cosine.
            EXPECT_NEAR(fresnel_dielectric(std::cos(theta_t), 1.0 / eta), outside, 1e-12);
        }
    }
}

TEST(Bravais, NormalPlaneGivesTheIndexItself) {
    for (double eta : kEtas) {
        EXPECT_NEAR(bravais_eta_perp(eta, 0.0), eta, 1e-15);
        EXPECT_NEAR(bravais_eta_par(eta, 0.0), eta, 1e-15);
    }
}

TEST(Bravais, ClosedFormsAndIdentities) {
    for (double eta : kEtas) {
        for (int i = -89; i <= 89; ++i) {
            const double theta = radians(i);
            const double s = std::sin(theta), c = std::cos(theta);
            const double perp = bravais_eta_perp(eta, theta);
            const double par = bravais_eta_par(eta, theta);
            EXPECT_NEAR(perp, std::sqrt(eta * eta - s * s) / c, 1e-12 * perp);
            EXPECT_NEAR(par, eta * eta * c / std::sqrt(eta * eta - s * s), 1e-12 * eta);
            // η'·η'' = η² (the square roots cancel), hence η' ≥ η ≥ η''.
            EXPECT_NEAR(perp * par, eta * eta, 1e-12 * eta * eta) << eta << " " << i;
            EXPECT_GE(perp, eta - 1e-12);
            EXPECT_LE(par, eta + 1e-12);
            // η'² cos²θ + sin²θ = η²: the projected refraction obeys Snell's law with η'.
            EXPECT_NEAR(perp * perp * c * c + s * s, eta * eta, 1e-10 * eta * eta);
            // Even in θ.
            EXPECT_DOUBLE_EQ(bravais_eta_perp(eta, -theta), perp);
            EXPECT_DOUBLE_EQ(bravais_eta_par(eta, -theta), par);
        }
        // η' grows monotonically with |θ|.
        double previous = eta;
        for (int i = 1; i <= 89; ++i) {
            const double perp = bravais_eta_perp(eta, radians(i));
            EXPECT_GT(perp, previous);
            previous = perp;
        }
        // Finite (if huge) at the pole.
        EXPECT_TRUE(std::isfinite(bravais_eta_perp(eta, kHalfPi)));
        EXPECT_TRUE(std::isfinite(bravais_eta_par(eta, kHalfPi)));
        EXPECT_GE(bravais_eta_par(eta, kHalfPi), 0.0);
    }
}

TEST(FresnelBravais, EqualIndicesMatchFresnelDielectric) {
    for (double eta : kEtas) {
        for (int i = -90; i <= 90; ++i) {
            const double gamma = radians(i);
            EXPECT_NEAR(fresnel_bravais(eta, eta, gamma), fresnel_dielectric(std::cos(gamma), eta),
                        1e-12)
                << eta << " " << i;
        }
    }
}

TEST(FresnelBravais, SplitsThePolarizations) {
    // Perpendicular polarization uses η', parallel uses η''.
    const double perp = 1.9, par = 1.3;
    for (int i = 0; i < 90; i += 5) {
        const double gamma = radians(i);
        EXPECT_NEAR(fresnel_bravais(perp, par, gamma),
                    0.5 * (reference_rs(gamma, perp) + reference_rp(gamma, par)), 1e-12);
    }
    // At η'''s Brewster angle only the s-part of η' remains.
    const double brewster = std::atan(par);
    EXPECT_NEAR(fresnel_bravais(perp, par, brewster), 0.5 * reference_rs(brewster, perp), 1e-12);
}

TEST(FresnelBravais, InternalReflectionIsStokesSymmetric) {
    // Marschner's internal factor F(1/η', 1/η'', γ_t) equals the external one at γ_i when
    // η' = η'' (sin γ_t = sin γ_i / η).
    for (double eta : kEtas) {
        for (int i = 0; i < 90; i += 3) {
            const double gamma_i = radians(i);
            const double gamma_t = std::asin(std::sin(gamma_i) / eta);
            EXPECT_NEAR(fresnel_bravais(1.0 / eta, 1.0 / eta, gamma_t),
                        fresnel_bravais(eta, eta, gamma_i), 1e-12);
        }
        // TIR for a 1/η index beyond the critical angle.
        EXPECT_DOUBLE_EQ(fresnel_bravais(1.0 / eta, 1.0 / eta, std::asin(1.0 / eta) + 1e-3), 1.0);
    }
}

}  // namespace
}  // namespace hairis
