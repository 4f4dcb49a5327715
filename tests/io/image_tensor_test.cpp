#include "io/image_tensor.hpp"

#include <gtest/gtest.h>

#include "support/expect_error.hpp"

namespace iesrgs {
namespace {

Image ramp(int width, int height) {
  Image image(width, height, 3);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = float(i % 97) / 90.f - 0.05f;
  return image;
}

TEST(ImageTensor, RoundTripKeepsEverySample) {
  const Image image = ramp(7, 5);
  const torch::Tensor tensor = to_tensor(image);
  ASSERT_EQ(tensor.sizes(), torch::IntArrayRef({1, 3, 5, 7}));
  EXPECT_EQ(tensor[0][2][4][6].item<float>(), image.at(6, 4, 2));
  EXPECT_EQ(to_image(tensor).data, image.data);
}

TEST(ImageTensor, TensorOwnsItsSamplesEvenForOnePixel) {
  torch::Tensor tensor;
  {
    Image pixel(1, 1, 3);
    pixel.data = {0.25f, 0.5f, 0.75f};
    tensor = to_tensor(pixel);
  }
  EXPECT_EQ(tensor[0][2][0][0].item<float>(), 0.75f);
}

TEST(ImageTensor, EightBitConversionMatchesToEightBit) {
  const Image image = ramp(3, 150);  // more rows than one band, values beyond [0, 1]
  EXPECT_EQ(to_image8(to_tensor(image)).data, to_8bit(image).data);
}

TEST(ImageTensor, NonRgbInputsAreErrors) {
  EXPECT_EQ(iesrgs::testing::error_message([] { to_tensor(Image(2, 2, 4)); }),
            "image conversion: expected 3 channels, got 4");
  EXPECT_EQ(iesrgs::testing::error_message([] {
              check_rgb_batch(torch::zeros({1, 3, 2, 2}, torch::kFloat64), "net");
            }),
            "net: expected a float32 CPU tensor");
}

}  // namespace
}  // namespace iesrgs
