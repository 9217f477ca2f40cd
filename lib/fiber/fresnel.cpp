#include "fiber/fresnel.h"

#include <algorithm>
#include <cmath>

namespace hairis {

namespace {

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
