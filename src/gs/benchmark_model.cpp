#include "gs/benchmark_model.hpp"

namespace iesrgs::gs {

GaussianModel benchmark_model(int64_t n) {
  torch::manual_seed(1);
  GaussianModel model;
  model.set_params({torch::randn({n, 3}), torch::rand({n, 1, 3}), torch::zeros({n, 15, 3}),
                    torch::zeros({n}), torch::full({n, 3}, -4.0f), torch::randn({n, 4})});
  for (int p = 0; p < kParamCount; ++p)
    model.param(Param(p)).mutable_grad() = torch::randn_like(model.param(Param(p))) * 1e-3;
  return model;
}

}  // namespace iesrgs::gs
