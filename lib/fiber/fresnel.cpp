#include "fiber/fresnel.h"

#include <algorithm>
#include <cmath>

namespace hairis {

namespace {

template <typename T>
T fresnel_dielectric_impl(T cos_i, T eta) {
    // Light arriving from inside sees the inverse index.
    if (cos_i < T(0)) {
        eta = T(1) / eta;
        cos_i = -cos_i;
    }
    const T sin2_t = (T(1) - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= T(1)) return T(1);  // total internal reflection
    const T cos_t = std::sqrt(T(1) - sin2_t);
    const T r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const T r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return T(0.5) * (r_s * r_s + r_p * r_p);
}

// Reflectance of one polarization; `parallel` selects which index multiplies which cosine.
double polarized_reflectance(double eta, double gamma, bool parallel) {
    const double cos_i = std::cos(gamma);
    const double sin_t = std::sin(gamma) / eta;
    if (std::fabs(sin_t) >= 1.0) return 1.0;
    const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
    const double r = parallel ? (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
                              : (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return r * r;
}

}  // namespace

float fresnel_dielectric(float cos_i, float eta) { return fresnel_dielectric_impl(cos_i, eta); }
double fresnel_dielectric(double cos_i, double eta) { return fresnel_dielectric_impl(cos_i, eta); }

double fresnel_bravais(double eta_perp, double eta_par, double gamma) {
    return 0.5 * (polarized_reflectance(eta_perp, gamma, false) +
                  polarized_reflectance(eta_par, gamma, true));
}

double bravais_eta_perp(double eta, double theta) {
    const double s = std::sin(theta);
    return std::sqrt(std::max(0.0, eta * eta - s * s)) / std::cos(theta);
}

double bravais_eta_par(double eta, double theta) {
    const double s = std::sin(theta);
    return eta * eta * std::cos(theta) / std::sqrt(std::max(1e-300, eta * eta - s * s));
}

}  // namespace hairis
