#pragma once
// Each subcommand lives in its own file and registers itself on the top-level app.
#include <CLI/CLI.hpp>

namespace iesrgs::cli {

void add_synth_command(CLI::App& app);
void add_info_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_train_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_depth_command(CLI::App& app);
void add_upscale_command(CLI::App& app);
void add_external_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_export_command(CLI::App& app);

}  // namespace iesrgs::cli
