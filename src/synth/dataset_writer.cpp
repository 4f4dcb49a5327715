#include "synth/dataset_writer.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/file_digest.hpp"
#include "io/image.hpp"
#include "io/npy.hpp"
#include "io/scene.hpp"
#include "synth/camera_path.hpp"
#include "synth/colmap_export.hpp"
#include "synth/renderer.hpp"

namespace iesrgs::synth {

namespace fs = std::filesystem;

namespace {

constexpr int kMaxSize = 8192;
constexpr int kMaxViews = 100000;
constexpr int kMaxSamples = 1024;
constexpr int kPointsPerView = 400;  // stand-in SfM points: 100 views give 40k points

int checked_grid(int samples) {
  const int grid = int(std::lround(std::sqrt(double(samples))));
  if (samples < 1 || samples > kMaxSamples || grid * grid != samples)
    fail("synthetic scene: samples per pixel must be a square number from 1 to {}, got {}",
         kMaxSamples, samples);
  return grid;
}

void check_options(const SynthOptions& options) {
  if (options.size < 8 || options.size > kMaxSize)
    fail("synthetic scene: size must be 8 to {} pixels, got {}", kMaxSize, options.size);
  if (options.train_views < 1 || options.train_views > kMaxViews)
    fail("synthetic scene: training views must be 1 to {}, got {}", kMaxViews, options.train_views);
  if (options.test_views < 0 || options.test_views > kMaxViews)
    fail("synthetic scene: test views must be 0 to {}, got {}", kMaxViews, options.test_views);
  // The capture holds out every 8th image from its first: one image alone would all be test.
  if (options.format == SynthFormat::Colmap && options.train_views + options.test_views < 2)
    fail(
        "synthetic scene: a COLMAP capture holds out its first image for test, so it needs at "
        "least 2 views and test views together, got {}",
        options.train_views + options.test_views);
}

struct SplitViews {
  const char* name;  // "train" or "test", the folder and the transforms file suffix
  std::vector<CameraPose> poses;
};

class DatasetWriter {
 public:
  DatasetWriter(const fs::path& dir, const SynthOptions& options, const ViewProgress& progress)
      : dir_(dir), scene_(make_synth_scene(options.seed)), progress_(progress) {
    settings_.width = settings_.height = options.size;
    settings_.grid =
        checked_grid(options.samples ? options.samples : default_samples(options.size));
    total_ = options.train_views + options.test_views;
  }

  // The views of every split, then their transforms files, the training split's last: a folder
  // with transforms_train.json holds a whole scene, and a stopped run leaves none.
  void write_blender(const std::vector<SplitViews>& splits) {
    std::vector<nlohmann::json> transforms;
    for (const SplitViews& split : splits) {
      nlohmann::json frames = nlohmann::json::array();
      for (size_t i = 0; i < split.poses.size(); ++i) {
        const std::string stem = std::string(split.name) + "/r_" + std::to_string(i);
        write_view(split.poses[i], stem);
        frames.push_back(
            {{"file_path", "./" + stem}, {"transform_matrix", split.poses[i].matrix()}});
      }
      transforms.push_back({{"camera_angle_x", settings_.camera_angle_x}, {"frames", frames}});
    }
    for (size_t k = splits.size(); k-- > 0;)
      write_file_atomically(dir_ / (std::string("transforms_") + splits[k].name + ".json"),
                            transforms[k].dump(4) + "\n");
  }

  // Opaque photos over black, as a camera would take them and as captures are trained; the model
  // is written last, so a complete sparse/0 means complete images.
  void write_colmap(const std::vector<CameraPose>& poses) {
    ColmapExport colmap(settings_, kPointsPerView);
    const float black[3] = {0, 0, 0};
    for (size_t i = 0; i < poses.size(); ++i) {
      const std::string stem = fmt::format("r_{:04d}", i);
      const RenderedView view = render(poses[i], dir_ / "depth" / (stem + ".npy"));
      write_png(dir_ / "images" / (stem + ".png"), composite_rgb(to_8bit(view.rgba), black));
      colmap.add_view(poses[i], view, stem + ".png");
    }
    colmap.write(dir_);
  }

 private:
  // Renders one view, writes its depth to `depth_path` and reports progress.
  RenderedView render(const CameraPose& pose, const fs::path& depth_path) {
    RenderedView view = render_view(scene_, pose, settings_);
    write_npy(depth_path, view.depth, {size_t(settings_.height), size_t(settings_.width)});
    ++done_;
    if (progress_) progress_(done_, total_);
    return view;
  }

  void write_view(const CameraPose& pose, const std::string& stem) {
    const RenderedView view = render(pose, dir_ / (stem + "_depth.npy"));
    write_png(dir_ / (stem + ".png"), view.rgba);
  }

  fs::path dir_;
  SynthScene scene_;
  RenderSettings settings_;
  const ViewProgress& progress_;
  int done_ = 0, total_ = 0;
};

// Records the options of the scene in a folder and the digests of the files that make the folder
// a scene, as synth wrote them: those, unchanged, are synth's to replace.
constexpr char kRecord[] = "synth.json";

// The files that make a folder a scene, in any format and COLMAP encoding, relative to it; synth
// writes some of them, never nerfstudio's transforms.json.
std::vector<std::string> index_files() {
  std::vector<std::string> files = {"transforms_train.json", "transforms_test.json",
                                    "transforms.json"};
  for (const char* folder : {"sparse/0/", "sparse/"})
    for (const char* name : {"cameras", "images", "points3D"})
      for (const char* extension : {".bin", ".txt"})
        files.push_back(std::string(folder) + name + extension);
  return files;
}

// sparse/ alone makes a COLMAP scene; kept when it holds anything else.
void remove_empty_sparse_folders(const fs::path& dir) {
  std::error_code ec;
  for (const fs::path& folder : {dir / "sparse" / "0", dir / "sparse"}) fs::remove(folder, ec);
}

// Refuses a folder holding a scene synth did not write, or has since changed (a capture's COLMAP
// model is not synth's to replace); in one it did, removes those files, so that until this scene
// is whole the folder is none, rather than the earlier cameras over some new images.
void replace_earlier_scene(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec) || !is_scene(dir)) return;
  const nlohmann::json record =
      fs::exists(dir / kRecord, ec)
          ? nlohmann::json::parse(read_file(dir / kRecord), nullptr, false)
          : nlohmann::json();
  const nlohmann::json written =
      record.is_object() ? record.value("files", nlohmann::json()) : nlohmann::json();
  std::vector<fs::path> present;
  for (const std::string& name : index_files()) {
    if (!fs::exists(dir / name, ec)) continue;
    if (!written.is_object() || written.value(name, std::string()) != file_digest(dir / name))
      fail_file(dir, fmt::format("holds a scene synth did not write ({} is not as {} records it); "
                                 "write the synthetic scene into another folder",
                                 name, kRecord));
    present.push_back(dir / name);
  }
  for (const fs::path& file : present) remove_earlier_output(file, "left by an earlier scene");
  remove_empty_sparse_folders(dir);
}

// Written once the scene is whole: its options, and the digests replace_earlier_scene checks.
void record_scene(const fs::path& dir, const SynthOptions& options) {
  nlohmann::json files = nlohmann::json::object();
  for (const std::string& name : index_files())
    if (fs::exists(dir / name)) files[name] = file_digest(dir / name);
  const nlohmann::json record = {
      {"format", options.format == SynthFormat::Colmap ? "colmap" : "blender"},
      {"size", options.size},
      {"views", options.train_views},
      {"test_views", options.test_views},
      {"seed", options.seed},
      {"samples", options.samples ? options.samples : default_samples(options.size)},
      {"files", files}};
  write_file_atomically(dir / kRecord, record.dump(2) + "\n");
}

}  // namespace

int default_samples(int size) {
  if (size <= 256) return 16;
  if (size <= 512) return 9;
  return 4;
}

void write_synth_dataset(const fs::path& dir, const SynthOptions& options,
                         const ViewProgress& progress) {
  check_options(options);
  DatasetWriter writer(dir, options, progress);
  replace_earlier_scene(dir);
  if (options.format == SynthFormat::Colmap)
    writer.write_colmap(train_orbit(options.train_views + options.test_views, options.seed));
  else
    writer.write_blender({{"train", train_orbit(options.train_views, options.seed)},
                          {"test", test_orbit(options.test_views)}});
  try {
    record_scene(dir, options);
  } catch (...) {
    // A scene without its record would be refused by the next synth as not synth's own.
    std::error_code ec;
    for (const std::string& name : index_files()) fs::remove(dir / name, ec);
    remove_empty_sparse_folders(dir);
    throw;
  }
}

}  // namespace iesrgs::synth
