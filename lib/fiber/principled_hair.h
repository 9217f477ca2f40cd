// Blender's Principled Hair BSDF node and Cycles' mapping of its inputs to the closure
// parameters (svm_node_closure_bsdf): the Chiang model (CLOSURE_BSDF_HAIR_PRINCIPLED_ID in
// 3.4, CLOSURE_BSDF_HAIR_CHIANG_ID from 4.0) and, from Blender 4.0, the Huang model
// (CLOSURE_BSDF_HAIR_HUANG_ID).
#pragma once

#include "fiber/chiang.h"
#include "fiber/huang.h"
#include "core/expected.h"
#include "core/math.h"

namespace hairis {

/// How the node colours the fiber (Blender's "parametrization" menu).
enum class HairParametrization {
    AbsorptionCoefficient,  ///< "Absorption Coefficient": σ_a given directly
    Melanin,                ///< "Melanin Concentration": eumelanin/pheomelanin, plus a tint
    Color,                  ///< "Direct Coloring": σ_a from the desired colour
};

/// The node's inputs with Blender's defaults (node_shader_bsdf_hair_principled.cc, unchanged
/// from 2.80 through 3.4). Only the inputs of the chosen parametrization are read, as
/// Blender hides the others.
struct PrincipledHairNode {
    HairParametrization parametrization = HairParametrization::Color;
    /// "Color" (Direct Coloring), scene-linear Rec.709; components in (0, 1].
    Rgb color{0.017513f, 0.005763f, 0.002059f};
    /// "Melanin" in [0, 1], perceptually linear amount of pigment.
    float melanin = 0.8f;
    /// "Melanin Redness" in [0, 1]: the pheomelanin fraction.
    float melanin_redness = 1.0f;
    /// "Tint" (Melanin Concentration), components in (0, 1].
    Rgb tint{1.0f, 1.0f, 1.0f};
    /// "Absorption Coefficient" (Absorption Coefficient), components >= 0.
    Rgb absorption_coefficient{0.245531f, 0.52f, 1.365f};
    /// "Roughness" in [0, 1].
    float roughness = 0.3f;
    /// "Radial Roughness" in [0, 1].
    float radial_roughness = 0.3f;
    /// "Coat" in [0, 1].
    float coat = 0.0f;
    /// "IOR", > 1 here (Blender allows [0, 1000]; the model needs η > 1).
    float ior = 1.55f;
    /// "Offset": the cuticle tilt in radians, [−π/2, π/2]; Blender's default is 2°.
    float offset = float(radians(2.0));
    /// "Random Color" in [0, 1] (Melanin Concentration only).
    float random_color = 0.0f;
    /// "Random Roughness" in [0, 1].
    float random_roughness = 0.0f;
    /// "Random" in [0, 1]: the per-strand random number (linked, or Cycles' curve random).
    float random = 0.0f;
    /// Which Cycles evaluates the node (Blender's version): where Chiang's tilt goes.
    ChiangTilt tilt = ChiangTilt::Incident;
    /// Huang only (Blender 4.0+): "Aspect Ratio", the ellipse's minor / major axis; Cycles
    /// renders a value b > 1 as 1/b and does not guard b <= 0.
    float aspect_ratio = 0.85f;
    /// Huang only: the lobe multipliers "Reflection", "Transmission" and "Secondary
    /// Reflection" (identifiers "R lobe", "TT lobe", "TRT lobe"). Cycles stores max(0, value)
    /// and allocates no closure when all three are <= 0.
    float reflection = 1.0f, transmission = 1.0f, secondary_reflection = 1.0f;

    /// The node as Blender creates it (Direct Coloring, every input at its default).
    static PrincipledHairNode cycles_default() { return {}; }
};

/// Cycles' SVM mapping of the node to the closure parameters: random factors
/// 1 + 2(random − 0.5)·random_{roughness,color}, melanin −log(max(1 − m, 1e-4)) split by
/// redness, colours through sigma_from_reflectance with the randomized radial roughness,
/// and roughness clamped into [0, 1] (ChiangFiber applies the remaining 0.001 floor).
/// Refuses NaN/inf and out-of-range inputs with a message naming the input.
Expected<ChiangParams> to_chiang_params(const PrincipledHairNode &node);

/// Cycles' SVM mapping of the node with the Huang model: the same random factors and
/// absorption as Chiang's, except that Direct Coloring and the Melanin tint invert the colour
/// with the randomized Roughness (Huang has no Radial Roughness); roughness clamped into
/// [0, 1] (HuangFiber applies the 0.001 floor); Aspect Ratio and the lobe multipliers passed
/// on, negative multipliers as 0. Refuses what to_chiang_params refuses (Radial Roughness and
/// Coat are not read), an aspect ratio that is not finite and > 0, a multiplier that is not
/// finite, and all three multipliers <= 0 (Cycles then allocates no closure: the strands
/// neither scatter nor let light through), each naming the input.
Expected<HuangParams> to_huang_params(const PrincipledHairNode &node);

namespace principled_hair {

/// Cycles' polynomial in the radial roughness β_n used to invert the colour:
/// ((((0.245β + 5.574)β − 10.73)β + 2.532)β − 0.215)β + 5.969.
double albedo_roughness_scale(double radial_roughness);
/// σ_a for a desired colour: (log(c) / albedo_roughness_scale(β_n))² per channel.
Rgb sigma_from_reflectance(Rgb color, double radial_roughness);
/// σ_a of the two melanins: eumelanin·(0.506, 0.841, 1.653) + pheomelanin·(0.343, 0.733, 1.924).
Rgb sigma_from_concentration(double eumelanin, double pheomelanin);

}  // namespace principled_hair

}  // namespace hairis
