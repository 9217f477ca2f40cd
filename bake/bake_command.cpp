// hairis-bake bake: tables for one fiber, written atomically as EXR.
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <iostream>

#include "commands.h"
#include "fiber_options.h"
#include "tables/bake.h"
#include "sampling/huang_table.h"
#include "tables/table_file.h"

namespace hairis::cli {

namespace {

struct BakeFlags {
    FiberOptions fiber;
    BakeOptions bake;
    std::string output;
    bool quiet = false;
};

// A progress bar on stderr, drawn only when stderr is a terminal.
class ProgressBar {
  public:
    explicit ProgressBar(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}
    void update(float fraction) {
        if (!enabled_) return;
        const int width = 40, filled = int(fraction * width + 0.5f);
        std::fprintf(stderr, "\r[%.*s%*s] %3d%%", filled, "########################################",
                     width - filled, "", int(fraction * 100.0f + 0.5f));
        std::fflush(stderr);
    }
    ~ProgressBar() {
        if (enabled_) std::fputc('\n', stderr);
    }

  private:
    bool enabled_;
};

int run_bake(const BakeFlags &flags) {
    Expected<FiberSpec> spec = flags.fiber.resolve();
    if (!spec) {
        std::cerr << "hairis-bake bake: " << spec.error().message << "\n";
        return kExitFailure;
    }
    Expected<std::unique_ptr<FiberModel>> model = spec.value().create_model();
    auto parameters = spec.value().parameters();
    if (!model || !parameters) {
        std::cerr << "hairis-bake bake: " << (!model ? model.error() : parameters.error()).message << "\n";
        return kExitFailure;
    }
    const auto start = std::chrono::steady_clock::now();
    // For the CLI tests: deliver a real SIGINT to ourselves after N progress reports, so the
    // interrupted path is tested deterministically (no timing races).
    const char *interrupt_env = std::getenv("HAIRIS_TEST_INTERRUPT_AFTER");
    const long interrupt_after = interrupt_env ? std::strtol(interrupt_env, nullptr, 10) : -1;
    long reports = 0;
    Expected<TableSet> tables = [&] {
        ProgressBar bar(!flags.quiet);
        return bake_tables(*model.value(), parameters.value(), flags.bake, [&](float f) {
            bar.update(f);
            if (interrupt_after >= 0 && reports++ == interrupt_after) std::raise(SIGINT);
            return !interrupted();
        });
    }();
    if (!tables) {
        if (interrupted()) {
            std::cerr << "hairis-bake bake: interrupted; nothing was written\n";
            return kExitInterrupted;
        }
        std::cerr << "hairis-bake bake: " << tables.error().message << "\n";
        return kExitFailure;
    }
    if (Status s = write_table_file(tables.value(), flags.output)) {
        std::cerr << "hairis-bake bake: " << s->message << "\n";
        return kExitFailure;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!flags.quiet) {
        const TableSet &t = tables.value();
        std::cerr << "hairis-bake bake: wrote " << flags.output << " (" << t.model << ", ";
        if (t.huang)
            std::cerr << t.huang->theta_o_count() << " theta_o x " << t.huang->phi_o_count() << " phi_o nodes, "
                      << t.huang->theta_i_count << " x " << t.huang->phi_count << " cells"
                      << (t.has_multiple() ? ", multiple part " + std::to_string(t.theta_r_count()) + " x " +
                                                 std::to_string(t.theta_i_count)
                                           : std::string());
        else
            std::cerr << t.theta_r_count() << " x " << t.theta_i_count << " x " << t.phi_count;
        std::cerr << ", " << seconds << " s)\n";
    }
    return 0;
}

}  // namespace

void add_bake_command(CLI::App &app, int &exit_code) {
    auto flags = std::make_shared<BakeFlags>();
    CLI::App *cmd = app.add_subcommand("bake", "bake sampling tables for one fiber into an EXR file");
    flags->fiber.add_to(*cmd, "cycles-default");
    BakeOptions &b = flags->bake;
    cmd->add_option("--theta-r", b.theta_r_count, "theta_r nodes over [-90, 90] degrees")
        ->check(CLI::Range(1, kMaxThetaRNodes))->capture_default_str();
    cmd->add_option("--theta-i", b.theta_i_count, "theta_i cells over [-90, 90] degrees")
        ->check(CLI::Range(2, kMaxTableAxisCells))->capture_default_str();
    cmd->add_option("--phi", b.phi_count, "phi cells over [-180, 180] degrees")
        ->check(CLI::Range(1, kMaxTableAxisCells))->capture_default_str();
    cmd->add_option("--quadrature", b.quadrature_points, "Gauss-Legendre points per cell and axis")
        ->check(CLI::Range(1, 16))->capture_default_str();
    cmd->add_option("--n-h", b.n_h_values, "strand counts of the multiple-scattering tables, increasing")
        ->check(CLI::Range(1, 1024))->delimiter(',')->capture_default_str();
    cmd->add_option("--source", b.source, "exact (the model's distributions) or gaussian (the seed's PDFs)")
        ->check(CLI::IsMember({"exact", "gaussian"}))->capture_default_str();
    cmd->add_option("--huang-theta-o", b.huang.theta_o, "Huang fibers: theta_o view nodes over [-90, 90] degrees")
        ->check(CLI::Range(1, kMaxThetaRNodes))->capture_default_str();
    cmd->add_option("--huang-phi-o", b.huang.phi_o, "Huang fibers: phi_o view nodes over [0, 90] degrees (1 if circular)")
        ->check(CLI::Range(1, kMaxPhiONodes))->capture_default_str();
    cmd->add_option("--huang-theta-i", b.huang.theta_i, "Huang fibers: theta_i cells over [-90, 90] degrees")
        ->check(CLI::Range(1, kMaxTableAxisCells))->capture_default_str();
    cmd->add_option("--huang-phi", b.huang.phi, "Huang fibers: phi_i - phi_o cells over [-180, 180] degrees")
        ->check(CLI::Range(1, kMaxTableAxisCells))->capture_default_str();
    cmd->add_flag("!--no-huang-multiple", b.huang_multiple,
                  "Huang fibers: bake the Huang table alone, without the multiple-scattering part that "
                  "integrator=dual_scattering samples (it takes several seconds)");
    cmd->add_flag("!--no-huang-f", b.huang_f,
                  "Huang fibers: bake no f part, so that renders shade with Cycles' noisy eval instead of the "
                  "baked expectation");
    cmd->add_option("--huang-f-refinement", b.huang_f_refinement,
                    "Huang fibers: multiplies the orders of the f part's quadrature, which leaves less error "
                    "towards single lights and bakes for longer")
        ->check(CLI::Range(1, kMaxHuangFRefinement))->capture_default_str();
    cmd->add_flag("--huang-absorption", b.huang_absorption,
                  "Huang fibers: also bake the absorption part, so that renders shade strands of other "
                  "absorption (Random Color, Hair Info) with baked values instead of Cycles' eval");
    cmd->add_option("--threads", b.threads, "worker threads, 0 for all cores (the output does not depend on it)")
        ->check(CLI::Range(0, 1024))->capture_default_str();
    cmd->add_option("--output,-o", flags->output, "the EXR file to write (atomically)")->required();
    cmd->add_flag("--quiet,-q", flags->quiet, "no progress bar or summary");
    cmd->callback([flags, &exit_code] { exit_code = run_bake(*flags); });
}

}  // namespace hairis::cli
