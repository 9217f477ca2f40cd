// Scattering distributions on grids: the seed's Figures 1–3, and the statistics of its
// Tables 1 and 2.
//
// Measure. Every grid value is a CELL AVERAGE PER UNIT SOLID ANGLE of ω_i:
//     value(cell) = (1/Ω_cell) ∫_cell S(ω_i) dω_i,   dω_i = cos θ_i dθ_i dφ,
// with Ω_cell = (sin θ_hi − sin θ_lo)·Δφ the exact solid angle of the cell, so that
//     Σ_cells value · cell_solid_angle = ∫_{S²} S dω_i,
// the directional albedo for the viewer at ω_r when S = f·cos θ_i. Cells are regular in
// θ_i ∈ [−π/2, π/2] (rows) and φ ∈ [−π, π] (columns); the integral inside each cell is a
// tensor Gauss–Legendre rule with `quadrature_points` nodes per axis (never a point sample),
// because these grids become piecewise-constant sampling tables.
//
//   S_direct(θ_i, φ_i | θ_r, φ_r)  = luminance(f(ω_i, ω_r)·|cos θ_i|)            (one fiber)
//   S_multiple(θ_i | θ_r, n_h)     = luminance(DualScattering::multiple_f_cos)   (azimuth-
//                                    averaged, so a 1D grid over θ_i; its cells are full
//                                    rings, Ω_cell = 2π (sin θ_hi − sin θ_lo))
//
// Conventions are frame.h's: ω_r is the direction towards the viewer (the seed's and
// Marschner's "r", our "o"); φ = φ_i − φ_r; the TT lobe of S_direct sits at φ = ±π.
//
// Determinism: the grids are computed in parallel with oneTBB, each cell by itself in a fixed
// order, so the numbers are bit-identical whatever the number of threads.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "fiber/dual_scattering.h"
#include "core/expected.h"
#include "fiber/fiber.h"

namespace hairis {

/// Largest number of cells along one axis and in a whole grid (checked before allocating:
/// 2^22 cells of 8 bytes are 32 MiB; 4096 × 4096 is refused).
inline constexpr int kMaxCellsPerAxis = 4096;
inline constexpr long long kMaxCells = 1LL << 22;
/// The seed's strand counts for the multiple-scattering distribution (Figure 3, Tables 1–2).
inline constexpr std::array<int, 5> kStrandCounts = {1, 2, 4, 8, 16};

/// Resolution of a (θ_i, φ) grid.
struct DirectGridSpec {
    int theta_count = 90;        ///< cells along θ_i over [−π/2, π/2], [1, 4096] (2° by default)
    int phi_count = 180;         ///< cells along φ over [−π, π], [1, 4096] (2° by default)
    int quadrature_points = 3;   ///< Gauss–Legendre nodes per axis inside a cell, [1, 16]
    int lobe = -1;               ///< −1: f_cos (all lobes); p ≥ 0: lobe_f_cos(p) only
    int orientation_count = 16;  ///< fiber orientations averaged by the relative-azimuth grid
                                 ///< when the model is not rotationally symmetric, [1, 1024]
};

/// Resolution of a θ_i grid.
struct ThetaGridSpec {
    int theta_count = 180;       ///< cells along θ_i over [−π/2, π/2], [1, 4096] (1° by default)
    int quadrature_points = 4;   ///< Gauss–Legendre nodes inside a cell, [1, 16]
};

/// Cell averages per unit solid angle on a regular (θ_i, φ) grid; row-major, θ_i rows.
struct Grid2D {
    int theta_count = 0;
    int phi_count = 0;
    std::vector<double> values;  ///< values[i * phi_count + j]

    double value(int i, int j) const { return values[std::size_t(i) * std::size_t(phi_count) + std::size_t(j)]; }
    double theta_lo(int i) const;      ///< lower θ_i edge of row i
    double theta_center(int i) const;
    double phi_lo(int j) const;        ///< lower φ edge of column j
    double phi_center(int j) const;
    double cell_solid_angle(int i) const;  ///< (sin θ_hi − sin θ_lo)·2π/phi_count
    /// Σ value · cell solid angle: the directional albedo.
    double integral() const;
};

/// Cell averages per unit solid angle on a regular θ_i grid (each cell a full ring in φ).
struct Grid1D {
    int theta_count = 0;
    std::vector<double> values;

    double theta_lo(int i) const;
    double theta_center(int i) const;
    double cell_solid_angle(int i) const;  ///< 2π (sin θ_hi − sin θ_lo)
    double integral() const;               ///< Σ value · cell solid angle
};

/// S_direct on the (θ_i, φ_i) grid for the viewer at (θ_r, φ_r); columns are the ABSOLUTE
/// azimuth φ_i ∈ [−π, π]. θ_r ∈ [−π/2, π/2]; use |θ_r| < π/2 for models that are singular
/// when the view runs along the fiber (the tests use ±89.5° for the seed's ±90°: at ±90° the
/// view runs along the fiber, φ_r is undefined and Marschner divides by cos²θ_d → 0).
Expected<Grid2D> direct_distribution(const FiberModel &model, double theta_r, double phi_r,
                                     const DirectGridSpec &spec = {});

/// S_direct on the (θ_i, φ = φ_i − φ_r) grid. For a rotationally symmetric model φ_r is
/// Cycles' −π/2 (any value gives the same numbers); otherwise the grid is the average over
/// spec.orientation_count viewer azimuths φ_r uniformly spaced over [−π, π) (the fiber's
/// orientation around its axis is unknown when sampling).
Expected<Grid2D> direct_distribution_relative(const FiberModel &model, double theta_r,
                                              const DirectGridSpec &spec = {});

/// The θ_i-profile of a 2D grid: the azimuthal average per unit solid angle of each row, so
/// that Grid1D::integral() equals Grid2D::integral().
Grid1D azimuthal_average(const Grid2D &grid);

/// S_multiple(θ_i | θ_r, n_h) on a θ_i grid, n_h ≥ 0 (the seed uses kStrandCounts).
Expected<Grid1D> multiple_distribution(const DualScattering &ds, double theta_r, int n_h,
                                       const ThetaGridSpec &spec = {});

/// Which 1D density over θ_i the statistics describe.
enum class ThetaDensity {
    /// m(θ_i) = value · dΩ/dθ_i = 2π cos θ_i · S̄(θ_i): the marginal density per radian of
    /// θ_i, the one a θ_i sampler must follow; its integral is the albedo.
    kMarginal,
    /// S̄(θ_i) itself (per steradian), as plotted in the seed's figures.
    kPerSteradian,
};

/// Peak, width and scale of a 1D distribution over θ_i (for the seed's Tables 1 and 2).
struct ThetaStats {
    double peak = 0;        ///< θ_i of the maximum (radians), refined by a parabola through
                            ///< the largest cell and its neighbours
    double stddev = 0;      ///< sqrt(∫ (θ_i − peak)² d / ∫ d): the standard deviation around
                            ///< the PEAK (not the mean), d the chosen density (radians)
    double fwhm_sigma = 0;  ///< full width at half maximum / (2√(2 ln 2)): the σ of a
                            ///< Gaussian with the same FWHM (half-maximum crossings linearly
                            ///< interpolated between cell centres); a side that reaches the
                            ///< domain's end before half maximum is replaced by the other
                            ///< side, and if both do the FWHM is taken as π (radians)
    double scale = 0;       ///< ∫ d dθ_i (kMarginal: the albedo)
    double maximum = 0;     ///< the density's largest cell value
};

/// Statistics of `grid` under the chosen density. Fails on an empty or all-zero grid.
Expected<ThetaStats> theta_stats(const Grid1D &grid, ThetaDensity density = ThetaDensity::kMarginal);

}  // namespace hairis
