// hairis-bake's subcommands, each registering itself on the CLI11 app.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace hairis::cli {

/// Exit codes: 0 success, 1 failure (a clear message on stderr), 2 bad usage (CLI11),
/// 130 interrupted.
inline constexpr int kExitFailure = 1;
inline constexpr int kExitInterrupted = 130;

void add_bake_command(CLI::App &app, int &exit_code);
void add_inspect_command(CLI::App &app, int &exit_code);
void add_figures_command(CLI::App &app, int &exit_code);
void add_fits_command(CLI::App &app, int &exit_code);

/// Writes fits.md, fits_multiple.csv and fits_direct.csv into `output`; returns an exit code.
int write_fit_tables(const std::string &output, const std::vector<std::string> &presets, int theta_count,
                     int phi_count);

/// True once SIGINT or SIGTERM arrived; long work polls it and stops cleanly.
bool interrupted();
/// Installs the SIGINT/SIGTERM handlers behind interrupted().
void install_interrupt_handlers();

}  // namespace hairis::cli
