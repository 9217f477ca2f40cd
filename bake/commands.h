// hairis-bake's subcommands, each registering itself on the CLI11 app.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "fiber/dual_scattering.h"
#include "fiber/fiber_spec.h"

namespace hairis::cli {

/// Exit codes: 0 success, 1 failure (a clear message on stderr), 2 bad usage (CLI11),
/// 130 interrupted.
inline constexpr int kExitFailure = 1;
inline constexpr int kExitInterrupted = 130;

void add_bake_command(CLI::App &app, int &exit_code);
void add_inspect_command(CLI::App &app, int &exit_code);
void add_figures_command(CLI::App &app, int &exit_code);
void add_fits_command(CLI::App &app, int &exit_code);

/// A fiber the seed's figures and fits are drawn for: the model and its dual-scattering tables.
struct FigureFiber {
    std::string label;  ///< the preset, and any settings applied over it
    std::unique_ptr<FiberModel> model;
    std::unique_ptr<DualScattering> dual;
    /// The narrowest lobe's width (radians) when the figures may use fewer points per cell
    /// (Huang's GGX lobes); 0: always the full rule.
    double lobe_width = 0;
    /// Gauss–Legendre points per axis in a cell of a theta_count × phi_count grid over
    /// [−π/2, π/2] × [−π, π]: 3, or fewer where the cells are narrow against lobe_width.
    int grid_points(int theta_count, int phi_count) const;
};
/// The model of `spec` and its dual-scattering tables. Huang is evaluated with the bake's
/// expectation rule (figures show what tables hold), its dual-scattering quadrature and figure
/// cells sized to its GGX lobes (see fits_command.cpp).
Expected<FigureFiber> make_figure_fiber(const FiberSpec &spec, const std::string &label);

/// Writes fits.md, fits_multiple.csv and fits_direct.csv into `output`; returns an exit code.
int write_fit_tables(const std::string &output, const std::vector<const FigureFiber *> &fibers, int theta_count,
                     int phi_count);

/// True once SIGINT or SIGTERM arrived; long work polls it and stops cleanly.
bool interrupted();
/// Installs the SIGINT/SIGTERM handlers behind interrupted().
void install_interrupt_handlers();

}  // namespace hairis::cli
