#include "priors/sr/bicubic.hpp"

#include "core/error.hpp"
#include "io/image_tensor.hpp"
#include "io/resize.hpp"

namespace iesrgs::priors::sr {

namespace {

class Bicubic final : public SrNet {
 public:
  explicit Bicubic(int scale) : scale_(scale) {}

  std::string name() const override { return "bicubic"; }
  int scale() const override { return scale_; }

  torch::Tensor upscale(const torch::Tensor& rgb) override {
    check_rgb_batch(rgb, name());
    const Image image = to_image(rgb);
    return to_tensor(resize_bicubic(image, image.width * scale_, image.height * scale_));
  }

 private:
  int scale_;
};

}  // namespace

std::unique_ptr<SrNet> make_bicubic(int scale) {
  if (scale < 1) fail("bicubic: invalid scale {}", scale);
  return std::make_unique<Bicubic>(scale);
}

}  // namespace iesrgs::priors::sr
