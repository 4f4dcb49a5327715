// iesrgs: low-resolution multi-view captures in, high-resolution 3D Gaussian Splatting out.
#include <fmt/core.h>
#include <fmt/format.h>
#include <omp.h>
#include <spdlog/spdlog.h>
#include <torch/torch.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "cli/commands.hpp"
#include "core/device.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/torch_error.hpp"
#include "io/atomic_file.hpp"

namespace {

// An option error in the form of every other error. CLI11 answers a misspelled command with "A
// subcommand is required" alone: the word it did not know and the commands it knows are named.
std::string option_error(const CLI::App* app, const CLI::Error& error) {
  const CLI::App* command = app;
  while (!command->get_subcommands().empty()) command = command->get_subcommands().back();
  const std::vector<std::string> unknown = command->remaining();
  if (error.get_name() != "RequiredError" || command->get_require_subcommand_min() == 0 ||
      command->get_subcommands().size() >= command->get_require_subcommand_min())
    return fmt::format("error: {} (--help lists the options)\n", error.what());
  if (!unknown.empty() && unknown.front().rfind('-', 0) == 0)
    return fmt::format("error: unknown option '{}' (--help lists the options)\n", unknown.front());
  std::vector<std::string> known;
  for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; }))
    known.push_back(sub->get_name());
  const std::string what = command == app ? "command" : command->get_name() + " mode";
  return fmt::format("error: {} (known: {})\n",
                     unknown.empty() ? fmt::format("no {} given", what)
                                     : fmt::format("unknown {} '{}'", what, unknown.front()),
                     fmt::join(known, ", "));
}

// Whether everything printed reached stdout: a full disk or a closed pipe behind it is a failure,
// never a success.
bool stdout_written() {
  return std::fflush(stdout) == 0 && !std::ferror(stdout);
}

// fmt says "cannot write to file" without naming it; CLI11's help says nothing at all.
std::string stdout_failure(const std::string& reason = std::strerror(errno)) {
  return "cannot write to standard output: " + reason;
}

}  // namespace

int main(int argc, char** argv) {
  // Progress reaches a pipe or a log as each line is printed, and a killed command keeps it.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // Ctrl-C outside training ends a command at once, without the file it was writing.
  iesrgs::end_on_signals(iesrgs::remove_temporaries_in_progress);
  CLI::App app{"iesrgs: super-resolution 3D Gaussian Splatting (IE-SRGS) on CPUs and GPUs"};
  // LibTorch's CPU ops (the networks) default to one thread here; give them the cores OpenMP
  // uses for our own kernels (OMP_NUM_THREADS still limits both).
  torch::set_num_threads(omp_get_max_threads());
  app.require_subcommand(1);
  // CLI11's exit codes stay; set before the subcommands are added, which copy it.
  app.failure_message(option_error);
  // Which device --device auto takes here, so a user sees at once whether the GPU is usable.
  app.set_version_flag("--version", [] {
    return fmt::format("iesrgs " IESRGS_VERSION "\nCUDA kernels: {}\n--device auto: {}",
                       iesrgs::cuda_kernels_built() ? "built" : "not built",
                       iesrgs::describe_device(iesrgs::parse_device("auto")));
  });
  app.add_flag_callback(
      "-v,--verbose", [] { spdlog::set_level(spdlog::level::debug); }, "Print debug messages");
  iesrgs::cli::add_synth_command(app);
  iesrgs::cli::add_info_command(app);
  iesrgs::cli::add_bench_command(app);
  iesrgs::cli::add_train_command(app);
  iesrgs::cli::add_render_command(app);
  iesrgs::cli::add_eval_command(app);
  iesrgs::cli::add_depth_command(app);
  iesrgs::cli::add_upscale_command(app);
  iesrgs::cli::add_external_command(app);
  iesrgs::cli::add_run_command(app);
  iesrgs::cli::add_export_command(app);
  // Whatever was printed before an error comes first, so the error is the last line.
  const auto report = [](const char* message) {
    std::fflush(stdout);
    std::fprintf(stderr, "error: %s\n", message);
    return 1;
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 && !stdout_written() ? report(stdout_failure().c_str()) : status;
  } catch (const iesrgs::Interrupted& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "interrupted: %s\n", e.what());
    return iesrgs::interrupt_exit_status();
  } catch (const std::system_error& e) {
    if (std::ferror(stdout)) return report(stdout_failure(e.code().message()).c_str());
    return report(iesrgs::current_exception_message().c_str());
  } catch (...) {
    return report(iesrgs::current_exception_message().c_str());
  }
  // A stop asked for as the last outputs were written (training's final checkpoint, a run's
  // table): they are complete, and the status says the signal came, so a script stops here too
  // (bash goes on after a command that exits 0).
  if (iesrgs::interrupt_requested()) {
    std::fprintf(stderr,
                 "interrupted: after the command had done its work; its outputs are whole\n");
    return iesrgs::interrupt_exit_status();
  }
  return stdout_written() ? 0 : report(stdout_failure().c_str());
}
