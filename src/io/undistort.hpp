#pragma once
// Undistortion of OpenCV-model (k1 k2 p1 p2) images to a pinhole image.
#include "io/camera.hpp"
#include "io/image.hpp"

namespace iesrgs {

// Resamples `image` (taken with `intrinsics` and `distortion`) into the pinhole camera with the
// same intrinsics: each output pixel is projected through the distortion and sampled bilinearly
// from the input; samples outside the input are clamped to its border.
Image8 undistort_image(const Image8& image, const Intrinsics& intrinsics,
                       const Distortion& distortion);

// The share of the output image (sampled at 128 x 128 points) whose samples fall outside the
// input, where the lens's image does not reach the frame's edge and the border's pixels repeat.
double share_sampled_outside(const Intrinsics& intrinsics, const Distortion& distortion);

}  // namespace iesrgs
