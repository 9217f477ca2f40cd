// Fresnel reflectance of a dielectric and Bravais' effective indices for a tilted cylinder.
#pragma once

#include <cmath>

namespace hairis {

namespace detail {
template <typename T>
inline T fresnel_dielectric_impl(T cos_i, T eta) {
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
}  // namespace detail

/// Unpolarized Fresnel reflectance at a dielectric interface with relative index eta
/// (inside / outside), for incidence cosine cos_i measured on the side the light comes
/// from. Total internal reflection returns 1. Same formula as Cycles' fresnel_dielectric_cos.
/// Inline: Huang's bake calls it per path and direction.
inline float fresnel_dielectric(float cos_i, float eta) { return detail::fresnel_dielectric_impl(cos_i, eta); }
inline double fresnel_dielectric(double cos_i, double eta) { return detail::fresnel_dielectric_impl(cos_i, eta); }

/// Fresnel reflectance with separate indices for the perpendicular (eta_perp) and parallel
/// (eta_par) polarizations, as Marschner 2003 (Eq. in §4.1) uses with the Bravais indices:
/// F = (F_s(eta_perp) + F_p(eta_par)) / 2 at incidence angle gamma (radians, in the normal
/// plane). Total internal reflection returns 1 for that polarization.
double fresnel_bravais(double eta_perp, double eta_par, double gamma);

/// Bravais' index for the perpendicular polarization: η' = sqrt(η² − sin²θ) / cos θ.
double bravais_eta_perp(double eta, double theta);
/// Bravais' index for the parallel polarization: η'' = η² cos θ / sqrt(η² − sin²θ).
double bravais_eta_par(double eta, double theta);

}  // namespace hairis
