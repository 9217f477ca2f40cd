// hairis-bake inspect: print a table file's metadata and validate it.
#include <cstdio>
#include <iostream>

#include "commands.h"
#include "core/math.h"
#include "tables/table_file.h"

namespace hairis::cli {

namespace {

int run_inspect(const std::string &path) {
    Expected<TableSet> t = read_table_file(path);
    if (!t) {
        std::cerr << "hairis-bake inspect: invalid: " << t.error().message << "\n";
        return kExitFailure;
    }
    const TableSet &s = t.value();
    std::printf("file:            %s\n", path.c_str());
    std::printf("format version:  %d\n", kTableFormatVersion);
    std::printf("model:           %s\n", s.model.c_str());
    std::printf("source:          %s\n", s.source.c_str());
    std::printf("parameters:\n");
    for (const auto &[name, value] : s.parameters) std::printf("  %-18s %.9g\n", name.c_str(), value);
    std::printf("theta_r nodes:   %d (%.2f .. %.2f deg)\n", s.theta_r_count(), degrees(s.theta_r_nodes.front()),
                degrees(s.theta_r_nodes.back()));
    std::printf("theta_i cells:   %d\n", s.theta_i_count);
    std::printf("phi cells:       %d\n", s.phi_count);
    std::printf("n_h values:     ");
    for (int n : s.n_h_values) std::printf(" %d", n);
    std::printf("\nimage:           %d x %d RGBA float\n", s.phi_count, s.theta_r_count() * s.theta_i_count);
    std::printf("valid:           yes (metadata, sizes, values and pixel hash checked)\n");
    return 0;
}

}  // namespace

void add_inspect_command(CLI::App &app, int &exit_code) {
    auto path = std::make_shared<std::string>();
    CLI::App *cmd = app.add_subcommand("inspect", "print a table file's metadata and validate it "
                                                  "(exit status 0 when valid)");
    cmd->add_option("file", *path, "the EXR table file")->required();
    cmd->callback([path, &exit_code] { exit_code = run_inspect(*path); });
}

}  // namespace hairis::cli
