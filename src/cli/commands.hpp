#pragma once
// Each subcommand lives in its own file and registers itself on the top-level app.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "train/trainer.hpp"

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

// A trained model given as its training folder (its point_cloud.ply) or a model file. Throws Error
// for a folder whose training has not finished.
inline std::filesystem::path model_file(const std::filesystem::path& path) {
  if (!std::filesystem::is_directory(path)) return path;
  const std::filesystem::path model = train::model_path(path);
  if (!std::filesystem::exists(model) && std::filesystem::exists(train::checkpoint_path(path)))
    fail_file(path, std::string("its training has not finished (a checkpoint, no "
                                "point_cloud.ply yet): ") +
                        (std::filesystem::exists(path / "stage.json")
                             ? "the iesrgs run, internal or fuse command that made it continues it"
                             : "the same train command with --resume continues it"));
  return model;
}

}  // namespace iesrgs::cli
