// Fresnel reflectance of a dielectric and Bravais' effective indices for a tilted cylinder.
#pragma once

namespace hairis {

/// Unpolarized Fresnel reflectance at a dielectric interface with relative index eta
/// (inside / outside), for incidence cosine cos_i measured on the side the light comes
/// from. Total internal reflection returns 1. Same formula as Cycles' fresnel_dielectric_cos.
float fresnel_dielectric(float cos_i, float eta);
double fresnel_dielectric(double cos_i, double eta);

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
