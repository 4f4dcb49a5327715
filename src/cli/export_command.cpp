// iesrgs export: a trained model in the format a viewer wants: .splat for the web viewers, .spz
// (compressed, with the view-dependent colour), or a .ply with Mip-Splatting's 3D filter baked
// in for any 3DGS viewer.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include "cli/commands.hpp"
#include "core/error.hpp"
#include "core/paths.hpp"
#include "io/atomic_file.hpp"
#include "io/model_file.hpp"
#include "io/ply.hpp"
#include "io/splat_file.hpp"
#include "io/spz_file.hpp"
#include "train/session.hpp"

namespace iesrgs::cli {

namespace {

struct ExportArgs {
  std::string model;
  std::string output;
};

void run_export(const ExportArgs& args) {
  const std::filesystem::path output = args.output;
  const std::string format = lowercase_extension(output);
  if (format != ".splat" && format != ".spz" && format != ".ply")
    fail_file(output, "unknown export format: the name must end in .splat, .spz or .ply");
  const std::filesystem::path model = train::trained_model_file(args.model);
  std::error_code ec;  // set, and false returned, when the output does not exist yet
  // A baked copy over a Mip-Splatting model would lose its 3D filter for good.
  if (std::filesystem::equivalent(model, output, ec))
    fail_file(output, "is the model being exported; write the export elsewhere");
  const SplatCloud cloud = read_model(model);
  // An empty .splat is an empty file, which no reader can tell from a damaged one.
  if (cloud.size() == 0) fail_file(model, "holds no Gaussians: nothing to export");
  remove_stale_temporaries_of(output);  // what an export killed mid-write left
  size_t written = cloud.size();
  if (format == ".splat")
    written = write_splat(output, cloud);
  else if (format == ".spz")
    written = write_spz(output, cloud);
  else
    write_ply_filter_baked(output, cloud);
  fmt::print("wrote {} Gaussians to {} ({} bytes)\n", written, output.string(),
             std::filesystem::file_size(output));
  if (cloud.background && format != ".ply")
    fmt::print(
        "note: a {} file has no place for the background the model was trained over; "
        "render it with --background {}\n",
        format, fmt::join(*cloud.background, ","));
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* command = app.add_subcommand(
      "export",
      "Write a trained model as .splat (web viewers), .spz (compressed) or a filter-baked .ply");
  command
      ->add_option("model", args->model, "Training output folder, a 3DGS .ply, an .spz or a .splat")
      ->required();
  command->add_option("output", args->output, "OUT.splat, OUT.spz or OUT.ply")->required();
  command->callback([args] { run_export(*args); });
}

}  // namespace iesrgs::cli
