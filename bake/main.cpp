// hairis-bake: bake, inspect and redraw the seed's figures from the command line.
#include <CLI/CLI.hpp>

#include <csignal>
#include <iostream>

#include "commands.h"

namespace hairis::cli {

namespace {
volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_signal(int) { g_interrupted = 1; }
}  // namespace

bool interrupted() { return g_interrupted != 0; }

void install_interrupt_handlers() {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
}

}  // namespace hairis::cli

int main(int argc, char **argv) {
    CLI::App app{"hairis-bake: sampling tables and scattering distributions for hair fibers"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("hairis-bake ") + HAIRIS_VERSION);
    int exit_code = 0;
    hairis::cli::add_bake_command(app, exit_code);
    hairis::cli::add_inspect_command(app, exit_code);
    hairis::cli::add_figures_command(app, exit_code);
    hairis::cli::add_fits_command(app, exit_code);
    hairis::cli::install_interrupt_handlers();
    // CLI11 would only say "A subcommand is required": name the word and the choices.
    bool known = argc < 2 || argv[1][0] == '-';
    for (const CLI::App *sub : app.get_subcommands([](CLI::App *) { return true; }))
        known = known || sub->get_name() == argv[1];
    if (!known) {
        std::cerr << "hairis-bake: unknown subcommand \"" << argv[1]
                  << "\"; use one of bake, inspect, figures, fits (see --help)\n";
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError &e) {
        return app.exit(e);  // names the flag and what it allows; exit code 2 style
    }
    return exit_code;
}
