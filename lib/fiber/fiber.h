// The interface every fiber scattering model implements (Marschner 2003, Chiang 2016), for
// its far field: f averaged over the offset h across the fiber.
#pragma once

#include <memory>
#include <string>

#include "core/frame.h"
#include "core/math.h"

namespace hairis {

class ChiangFiber;
class HuangFiber;

/// Lobe indices shared by both models: p = number of internal path segments.
enum LobeIndex : int { kLobeR = 0, kLobeTT = 1, kLobeTRT = 2, kLobeResidual = 3 };

/// A lobe's longitudinal shape as a Gaussian in θ_h: shift α_p and standard deviation β_p
/// (radians). Dual scattering averages these; for Chiang β_p = sqrt(v_p).
struct LobeShape {
    float alpha = 0;
    float beta = 0;
};

/// A model's far field seen from one ω_o: what depends on ω_o alone is computed once, so
/// sweeping many ω_i (tables, dual scattering) pays for it once.
class FarFieldView {
  public:
    virtual ~FarFieldView() = default;
    /// Lobe p's f_p(ω_i, ω_o)·|cos θ_i| (zero for p outside the model's lobes).
    virtual Rgb lobe_f_cos(int p, Vec3 wi) const = 0;

    /// True when every lobe's f_p·|cos θ_i| factors as longitudinal(p, θ_i) × azimuthal(p, φ),
    /// φ = φ_i − φ_o (Chiang: M_p and the h-averaged A_p·N_p): sweeps can form outer products.
    virtual bool separable() const { return false; }
    /// The θ_i factor of lobe p (separable views only).
    virtual double longitudinal(int /*p*/, double /*theta_i*/) const { return 0.0; }
    /// The φ factor of lobe p, RGB (separable views only).
    virtual Rgb azimuthal(int /*p*/, double /*phi*/) const { return {}; }
};

/// A single hair fiber's far-field scattering function.
///
/// Directions are unit vectors in the fiber frame of frame.h (x along the tangent), pointing
/// away from the shading point: wi towards the light, wo towards the viewer. Every value is
/// f(ω_i, ω_o)·|cos θ_i|, the integrand of L_o = ∫ f L_i |cos θ_i| dω_i per unit solid angle,
/// the quantity Cycles' bsdf_principled_hair_eval returns.
class FiberModel {
  public:
    virtual ~FiberModel() = default;

    /// Stable identifier written into table metadata: "marschner2003" or "chiang2016".
    virtual std::string name() const = 0;

    /// Number of lobes: 3 (R, TT, TRT) for Marschner, 4 (with the residual) for Chiang.
    virtual int lobe_count() const = 0;

    /// The far field seen from ω_o. The default evaluates lobe_f_cos(p, wi, wo) per call.
    virtual std::unique_ptr<const FarFieldView> view(Vec3 wo) const;

    /// Far-field f_p(ω_i, ω_o)·|cos θ_i| of lobe p (averaged over the offset h).
    virtual Rgb lobe_f_cos(int p, Vec3 wi, Vec3 wo) const = 0;

    /// Far-field f(ω_i, ω_o)·|cos θ_i|: the sum over all lobes.
    virtual Rgb f_cos(Vec3 wi, Vec3 wo) const {
        Rgb sum;
        for (int p = 0; p < lobe_count(); ++p) sum += lobe_f_cos(p, wi, wo);
        return sum;
    }

    /// Longitudinal shift and width of lobe p, for dual scattering.
    virtual LobeShape lobe_shape(int p) const = 0;
    /// False when lobe_shape() is only a rough guess (lobes that are not Gaussians in θ_h):
    /// dual scattering then measures each lobe's shift and width from f itself.
    virtual bool lobe_shapes_analytic() const { return true; }

    /// True when f depends on φ_i and φ_o only through φ_i − φ_o (false for an elliptical
    /// Marschner fiber, whose response also depends on the half angle).
    virtual bool rotationally_symmetric() const { return true; }

    /// The fraction of the fiber's width (its curve's radius, offsets h ∈ [−1, 1]) that a ray
    /// along ±w meets the fiber in, in [0, 1]; rays through the rest pass unscattered. 1 for a
    /// fiber that fills its curve; Huang's ellipse seen along w (Cycles makes hits outside it
    /// transparent). f is per hit inside that fraction.
    virtual double projected_width(Vec3 /*w*/) const { return 1.0; }

    /// This model as a ChiangFiber, or null (what a bake adds Chiang's near-field table for).
    virtual const ChiangFiber *as_chiang() const { return nullptr; }
    /// This model as a HuangFiber, or null (a Huang fiber bakes a Huang table instead).
    virtual const HuangFiber *as_huang() const { return nullptr; }
};

}  // namespace hairis
