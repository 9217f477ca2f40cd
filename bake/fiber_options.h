// The fiber flags shared by the subcommands: --preset, --param-file, --set key=value.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "fiber/fiber_spec.h"

namespace hairis::cli {

struct FiberOptions {
    std::string preset = "cycles-default";
    std::string param_file;
    std::vector<std::string> settings;  ///< key=value

    /// Registers --preset, --param-file and --set on `cmd`.
    void add_to(CLI::App &cmd, const std::string &default_preset);
    /// The preset, then the parameter file, then each --set, in that order.
    Expected<FiberSpec> resolve() const;
};

}  // namespace hairis::cli
