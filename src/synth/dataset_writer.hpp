#pragma once
// Writes the synthetic scene as a dataset, in one of two layouts:
// - NeRF Synthetic: transforms_{train,test}.json, RGBA PNGs <split>/r_<i>.png with a transparent
//   background, and ground-truth depth <split>/r_<i>_depth.npy (float32, height x width, 0 where
//   nothing is hit);
// - COLMAP: one capture of train + test views over the upper hemisphere as opaque photos
//   images/r_<iiii>.png (black background) with depth in depth/r_<iiii>.npy, and sparse/0 holding
//   the cameras, poses and surface points standing in for SfM points. The reader's every-8th-image
//   hold-out makes its test split.
#include <cstdint>
#include <filesystem>
#include <functional>

namespace iesrgs::synth {

enum class SynthFormat { Blender, Colmap };

struct SynthOptions {
  SynthFormat format = SynthFormat::Blender;
  int size = 800;  // width and height in pixels
  int train_views = 100;
  int test_views = 50;
  uint64_t seed = 0;  // picks the layout, colours and patterns; equal seeds give equal files
  int samples = 0;    // per pixel, a square number (1, 4, 9, ...); 0 = default_samples(size)
};

// Fewer samples per pixel as the images grow, so every size renders in similar time.
int default_samples(int size);

// Called after each written view with the number written so far and the total.
using ViewProgress = std::function<void(int done, int total)>;

// Throws Error for options out of range, for files that cannot be written, and for a folder
// holding a scene synth did not write. An earlier synthetic scene's transforms files or COLMAP
// model are removed before the views are written, and this scene's written after them, so a
// folder that loads as a scene holds a whole one. synth.json, written last, records the options
// and the digests of those files, by which the next synth knows them for its own.
void write_synth_dataset(const std::filesystem::path& dir, const SynthOptions& options,
                         const ViewProgress& progress = {});

}  // namespace iesrgs::synth
