#pragma once
// A LibTorch network with loaded weights behind the SrNet interface: the input is padded as the
// network needs it, and the output cropped back to scale times the input's size.
#include <torch/torch.h>

#include <functional>
#include <string>
#include <utility>

#include "io/image_tensor.hpp"
#include "priors/compute_device.hpp"
#include "priors/sr/sr_net.hpp"

namespace iesrgs::priors::sr {

// Pads a (1, 3, H, W) input to a size the network takes; an empty one pads nothing.
using InputPad = std::function<torch::Tensor(const torch::Tensor&)>;

template <class Net>
class NetworkSr final : public SrNet {
 public:
  // `channels_last`: weights and activations in NHWC order, oneDNN's native layout, so that
  // activations are not reordered around every convolution (PAN runs about 25% faster on a CPU;
  // SAFMN and IMDN are unaffected). Only for networks of convolutions.
  NetworkSr(std::string name, Net net, int scale, InputPad pad = {}, bool channels_last = true)
      : name_(std::move(name)),
        net_(std::move(net)),
        scale_(scale),
        pad_(std::move(pad)),
        channels_last_(channels_last) {
    net_->eval();
    if (channels_last_)
      for (torch::Tensor& parameter : net_->parameters())
        if (parameter.dim() == 4)
          parameter.set_data(parameter.contiguous(torch::MemoryFormat::ChannelsLast));
  }

  std::string name() const override { return name_; }
  int scale() const override { return scale_; }

  torch::Tensor upscale(const torch::Tensor& rgb) override {
    check_rgb_batch(rgb, name_);
    torch::NoGradGuard no_grad;
    return on_compute_device(*net_, rgb, [&](const torch::Tensor& x) {
      const torch::Tensor padded = pad_ ? pad_(x) : x;
      return net_
          ->forward(channels_last_ ? padded.contiguous(torch::MemoryFormat::ChannelsLast) : padded)
          .narrow(2, 0, rgb.size(2) * scale_)
          .narrow(3, 0, rgb.size(3) * scale_)
          .contiguous();
    });
  }

 private:
  std::string name_;
  Net net_;
  int scale_;
  InputPad pad_;
  bool channels_last_;
};

}  // namespace iesrgs::priors::sr
