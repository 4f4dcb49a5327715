// iesrgs eval: PSNR / SSIM (and LPIPS when its weights are at hand) of rendered images against
// their ground truth, per view and averaged, as JSON and CSV.
#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/scene_options.hpp"
#include "cli/shared_options.hpp"
#include "cli/validators.hpp"
#include "core/error.hpp"
#include "core/paths.hpp"
#include "eval/lpips.hpp"
#include "eval/metrics.hpp"
#include "io/atomic_file.hpp"
#include "io/scene.hpp"
#include "io/view_images.hpp"

namespace iesrgs::cli {

namespace {

struct EvalArgs {
  std::string renders;
  std::string ground_truth;
  std::string output;
  std::string split = "test";
  std::optional<int> test_every;
  int downscale = 1;
  std::string background = "auto";
  std::string lpips = "alex";
};

// Render files by stem, sorted; a render folder with an rgb/ subfolder (iesrgs render's layout)
// is read from there.
std::vector<std::filesystem::path> render_files(std::filesystem::path dir) {
  if (std::filesystem::is_directory(dir / "rgb")) dir /= "rgb";
  std::error_code ec;
  if (!std::filesystem::exists(dir, ec)) fail_file(dir, "renders not found");
  if (!std::filesystem::is_directory(dir, ec)) fail_file(dir, "is not a folder of rendered images");
  std::vector<std::filesystem::path> files = image_files_in(dir);
  // a.png and a.jpg would both be scored as view a, which would count twice in the mean.
  if (const auto shared = first_shared_stem(files))
    fail_file(dir, fmt::format("{} and {} are both renders of view {}; keep one",
                               shared->first.filename().string(),
                               shared->second.filename().string(), shared->first.stem().string()));
  return files;
}

// The background a render.json records, when it holds three numbers in [0, 1].
std::optional<std::array<float, 3>> recorded_background(const nlohmann::json& report) {
  const auto found = report.find("background");
  if (found == report.end() || !found->is_array() || found->size() != 3) return std::nullopt;
  std::array<float, 3> background{};
  for (size_t c = 0; c < 3; ++c) {
    const nlohmann::json& value = (*found)[c];
    if (!value.is_number() || !(value.get<double>() >= 0 && value.get<double>() <= 1))
      return std::nullopt;
    background[c] = value.get<float>();
  }
  return background;
}

// What a render.json says of the views and their background, where it says it.
struct RenderRecord {
  std::optional<std::array<float, 3>> background;
  std::optional<int> test_every;  // of the scene the views were chosen from
};

// Refuses a render that `iesrgs render` did not finish, and one of other cameras than the ground
// truth's split, as its render.json records them: names alone do not tell (NeRF Synthetic's
// splits both start at r_0). Returns the background the renders were drawn over, as recorded.
RenderRecord check_render_record(const EvalArgs& args) {
  std::filesystem::path folder = args.renders;
  if (!folder.has_filename()) folder = folder.parent_path();  // given as "out/rgb/"
  if (folder.filename() == "rgb" && !std::filesystem::exists(folder / "render.json"))
    folder = folder.parent_path();
  const std::filesystem::path record = folder / "render.json";
  if (!std::filesystem::exists(record)) return {};
  const nlohmann::json report = nlohmann::json::parse(read_file(record), nullptr, false);
  if (!report.is_object()) return {};
  if (const auto finished = report.find("finished"); finished != report.end() && *finished == false)
    fail_file(record, "this render did not finish: render again before scoring it");
  if (is_scene(args.ground_truth)) {
    if (report.contains("path"))
      fail_file(record, "these renders are frames of a camera path, which have no ground truth");
    const auto recorded = report.find("split");
    const std::string split = recorded != report.end() && recorded->is_string()
                                  ? recorded->get<std::string>()
                                  : args.split;  // an older or edited record
    if (split != args.split)
      fail_file(record, fmt::format("these renders are of the {} split, and --split {} would score "
                                    "them against other views of the same names; use --split {}",
                                    split, args.split, split));
  }
  const auto test_every = report.find("test_every");
  return {recorded_background(report),
          test_every != report.end() && test_every->is_number_integer() && *test_every >= 1
              ? std::optional<int>(test_every->get<int>())
              : std::nullopt};
}

// Ground truth for a render stem: a scene's camera of that name (at --downscale, composited over
// the background), or an image of that stem in a plain folder.
class GroundTruth {
 public:
  GroundTruth(const EvalArgs& args, const SceneOptions& options)
      : root_(args.ground_truth), test_every_(options.test_every) {
    if (!is_scene(root_) && !std::filesystem::is_directory(root_))
      fail_file(root_, "ground truth not found: neither a scene nor a folder of images");
    if (is_scene(root_)) {
      scene_.emplace(load_scene(root_, options));
      background_ = scene_->background;
      images_.emplace(*scene_);
      const Split split = args.split == "train" ? Split::Train : Split::Test;
      for (const Camera* camera : scene_->split(split)) {
        cameras_[camera->name] = camera;
        names_.push_back(camera->name);
      }
    } else {
      // A plain folder of RGBA images is taken for NeRF Synthetic's.
      background_ = options.background.value_or(std::array<float, 3>{1, 1, 1});
      for (const std::filesystem::path& image : image_files_in(root_))
        names_.push_back(image.stem().string());
    }
  }

  const float* background() const { return background_.data(); }

  // The ground truth's views (the split's, or the folder's images) that no render was scored
  // against.
  std::vector<std::string> unscored(const std::vector<eval::ViewMetrics>& scored) const {
    std::vector<std::string> names;
    for (const std::string& name : names_)
      if (std::none_of(scored.begin(), scored.end(),
                       [&](const eval::ViewMetrics& v) { return v.name == name; }))
        names.push_back(name);
    return names;
  }

  Image get(const std::string& name) {
    if (scene_) {
      const auto found = cameras_.find(name);
      if (found == cameras_.end())
        fail_file(root_, fmt::format("has no view named \"{}\" in the chosen split{}", name,
                                     scene_->format == "blender"
                                         ? ""
                                         : fmt::format(" (--test-every {} here, where the "
                                                       "scene lists no split: renders made with "
                                                       "another?)",
                                                       test_every_)));
      return *images_->rgb(*found->second);
    }
    for (const char* ext : kImageExtensionSpellings) {
      const std::filesystem::path path = root_ / (name + ext);
      if (std::filesystem::exists(path))
        return composite_rgb(read_image8(path), background_.data());
    }
    fail_file(root_ / name, "no ground-truth image of this name (.png or .jpg)");
  }

 private:
  std::filesystem::path root_;
  std::array<float, 3> background_{};
  int test_every_;
  std::optional<Scene> scene_;
  std::optional<ViewImages> images_;
  std::map<std::string, const Camera*> cameras_;
  std::vector<std::string> names_;  // in the split's or the folder's order
};

// The report's path without .json and .csv. Never over the renders' record (eval's own check of
// them) nor into a scene's own folder, where it could replace the scene's transforms.
std::filesystem::path report_base(const EvalArgs& args) {
  namespace fs = std::filesystem;
  fs::path base = args.output.empty() ? fs::path(args.renders) / "metrics" : fs::path(args.output);
  // A folder given as the output holds the report under the default name, not as ".json".
  if (!base.has_filename() || fs::is_directory(base)) base /= "metrics";
  // The report is two files, so a path naming one of them names both.
  if (base.extension() == ".json" || base.extension() == ".csv") base.replace_extension();
  if (resolved_path(fs::path(base).concat(".json")) ==
      resolved_path(fs::path(args.renders) / "render.json"))
    fail_file(base, "would replace the renders' render.json; name the report otherwise");
  // Resolved before taking the parent: a bare name's parent is "", which names no folder.
  const fs::path truth = resolved_path(args.ground_truth);
  if (is_scene(truth) && resolved_path(base).parent_path() == scene_folder(truth))
    fail_file(base,
              "is in the scene's own folder, whose files the report could replace; write "
              "it elsewhere (a folder inside it will do)");
  return base;
}

void run_eval(const EvalArgs& args) {
  const RenderRecord rendered = check_render_record(args);
  SceneArgs scene_args;
  scene_args.options.downscale = args.downscale;
  scene_args.options.test_every =
      args.test_every.value_or(rendered.test_every.value_or(scene_args.options.test_every));
  scene_args.background = args.background;
  SceneOptions options = scene_args.resolved();
  // The ground truth over the background the renders were drawn over, as 3DGS scores its renders.
  if (!options.background) options.background = rendered.background;
  const std::filesystem::path base = report_base(args);
  // Before the scoring, which LPIPS makes long. The two files share their folder.
  require_writable(base.string() + ".json");
  GroundTruth truth(args, options);
  const eval::LoadedLpips lpips = eval::load_default_lpips(args.lpips);
  eval::MetricsReport report;
  const std::vector<std::filesystem::path> files = render_files(args.renders);
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string name = files[i].stem().string();
    // RGBA renders (other tools save them) are composited like the ground truth.
    const Image render = composite_rgb(read_image8(files[i]), truth.background());
    const Image reference = truth.get(name);
    try {
      report.views.push_back(eval::measure_view(name, render, reference, lpips.get()));
    } catch (const Error& e) {
      fail_file(files[i], e.what());
    }
    if ((i + 1) % 25 == 0 || i + 1 == files.size())
      fmt::print("evaluated {}/{} views\n", i + 1, files.size());
  }
  // A mean over part of a split is not the split's score: say so, in the report and next to the
  // numbers.
  report.lpips_status = eval::lpips_status(lpips, report.views);
  report.unscored = truth.unscored(report.views);
  const std::vector<std::string>& unscored = report.unscored;
  eval::write_report(base, report);
  if (!unscored.empty())
    fmt::print(
        "note: {} of {} {} no render and {} not in the mean: {}{}\n",
        unscored.size() == 1 ? "1 view" : fmt::format("{} views", unscored.size()),
        is_scene(args.ground_truth) ? "the " + args.split + " split" : args.ground_truth,
        unscored.size() == 1 ? "has" : "have", unscored.size() == 1 ? "is" : "are",
        fmt::join(unscored.begin(), unscored.begin() + std::min<size_t>(5, unscored.size()), ", "),
        unscored.size() > 5 ? ", ..." : "");
  const eval::ViewMetrics mean = report.mean();
  fmt::print("{} view{}: PSNR {:.3f} dB, SSIM {:.4f}, LPIPS {}\nwrote {}.json and .csv\n",
             report.views.size(), report.views.size() == 1 ? "" : "s", mean.psnr, mean.ssim,
             mean.lpips ? fmt::format("{:.4f}", *mean.lpips) : report.lpips_status, base.string());
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* command =
      app.add_subcommand("eval", "PSNR / SSIM / LPIPS of renders against ground truth");
  command
      ->add_option("renders", args->renders, "Folder of rendered images (or iesrgs render output)")
      ->required();
  command
      ->add_option("ground_truth", args->ground_truth,
                   "Scene (its --split views at --downscale) or a folder of images")
      ->required();
  command
      ->add_option("-o,--output", args->output,
                   "Report path (.json and .csv are added), or a folder for metrics.json and .csv "
                   "(default <renders>/metrics)")
      ->check(kNonEmptyPath);
  command->add_option("--split", args->split, "Scene split to compare with")
      ->check(CLI::IsMember({"train", "test"}))
      ->capture_default_str();
  command
      ->add_option("--test-every", args->test_every,
                   "Hold out every k-th image for test when the format has no test split "
                   "(default: the renders' own, which iesrgs render records, else 8)")
      ->check(kPositive);
  command->add_option("--downscale", args->downscale, "Ground-truth scene resolution 1/k")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--background", args->background,
                   "Background for RGBA renders and ground truth: white, black, r,g,b or auto "
                   "(the one the renders were drawn over, which iesrgs render records, else as "
                   "a scene's: white for NeRF Synthetic and for a plain folder, black for "
                   "captures)")
      ->capture_default_str();
  add_lpips_option(*command, args->lpips);
  command->callback([args] { run_eval(*args); });
}

}  // namespace iesrgs::cli
