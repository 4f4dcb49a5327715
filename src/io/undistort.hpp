#pragma once
// Undistortion of lens-distorted (OpenCV / COLMAP model) images to pinhole images.
#include <optional>

#include "io/camera.hpp"
#include "io/image.hpp"

namespace iesrgs {

// Resamples `image` (taken with `lens` and `distortion`) into the pinhole camera `pinhole` of the
// same size: each output pixel is projected through the distortion and sampled bilinearly from
// the input; samples outside the input are clamped to its border.
Image8 undistort_image(const Image8& image, const Intrinsics& lens, const Distortion& distortion,
                       const Intrinsics& pinhole);

// The pinhole camera of the lens's image size that sees only what the lens saw, as widely as that
// allows: the rectangle inside the frame's edges once undistorted, as OpenCV's
// getOptimalNewCameraMatrix with alpha 0 makes it for nerfstudio and gsplat. None when the
// distortion cannot be inverted at the frame's edges.
std::optional<Intrinsics> pinhole_within_lens(const Intrinsics& lens, const Distortion& distortion);

}  // namespace iesrgs
