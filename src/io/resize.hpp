#pragma once
// Image resampling that matches PIL's Image.resize(size, Image.BICUBIC) (Pillow 9.4: antialiased,
// a = -0.5, support scaled with the reduction factor), used to make the LR inputs of the benchmark
// protocol exactly as the research code does.
#include "io/image.hpp"

namespace iesrgs {

// 1-4 channels, 8-bit in and out, bit-exact with PIL (same fixed-point weights, rounding and
// clipping, horizontal pass first). Images with alpha (2 or 4 channels) are resampled
// premultiplied through PIL's own 8-bit conversions, as PIL does for LA / RGBA ("La" / "RGBa").
// The same size returns an unchanged copy; a target size below 1 throws Error.
Image8 resize_bicubic(const Image8& image, int width, int height);

// Float variant with the same filter weights and no quantization: channels resampled
// independently (no premultiplication) and results not clipped, so sharp edges may overshoot
// [0, 1] slightly.
Image resize_bicubic(const Image& image, int width, int height);

}  // namespace iesrgs
