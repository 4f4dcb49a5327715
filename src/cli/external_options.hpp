#pragma once
// The external-knowledge options `iesrgs external` and `iesrgs run` share.
#include <CLI/CLI.hpp>

#include "pipeline/external_stage.hpp"

namespace iesrgs::cli {

// --sr-model, --sr-weights, --tile, --depth-model, --depth-weights (not --scale: commands differ).
void add_external_options(CLI::App& command, pipeline::ExternalOptions& options);

}  // namespace iesrgs::cli
