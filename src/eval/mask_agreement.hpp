#pragma once
// How well IE-SRGS's discrepancy mask finds the pixels where the external image is wrong, the
// check of the paper's supplementary: the mask M = [D(I_image, E_image) >= T] against the mask
// the HR ground truth gives, G = [D(truth, E_image) >= T], and whether the internal image is in
// fact the closer reference where M picks it; and how close each reference is to the truth:
// E_image, I_image, the fused reference the mask-guided loss pulls towards (I_image on M,
// E_image elsewhere) and the best reference a mask could give by the L1 the loss trains with (the
// oracle mask: I_image wherever its absolute error is the smaller). Benchmarks only: it needs the
// HR training views.
#include <torch/types.h>

#include <cstdint>

namespace iesrgs::eval {

// Pixel counts, summed over views.
struct MaskCounts {
  int64_t pixels = 0;
  int64_t values = 0;           // pixels times channels, what the squared errors sum over
  int64_t mask = 0;             // |M|
  int64_t truth_mask = 0;       // |G|
  int64_t both = 0;             // |M and G|
  int64_t closer = 0;           // pixels where |I - truth| < |E - truth| (channel means)
  int64_t internal_closer = 0;  // of them, those in M
  // Squared errors against the truth, summed over every channel value.
  double external_error = 0, internal_error = 0, fused_error = 0, oracle_error = 0;

  MaskCounts& operator+=(const MaskCounts& other);
  double mask_share() const { return share(mask, pixels); }
  double truth_mask_share() const { return share(truth_mask, pixels); }
  double precision() const { return share(both, mask); }  // of M, the share inside G
  double recall() const { return share(both, truth_mask); }
  double iou() const { return share(both, mask + truth_mask - both); }
  double internal_closer_share() const { return share(internal_closer, mask); }
  double oracle_mask_share() const { return share(closer, pixels); }
  // PSNR of each reference over all pixels and channels of every view pooled: never above the
  // mean of per-view PSNRs that eval reports for renders, and below it where views differ.
  double external_psnr() const { return psnr(external_error); }
  double internal_psnr() const { return psnr(internal_error); }
  double fused_psnr() const { return psnr(fused_error); }
  double oracle_psnr() const { return psnr(oracle_error); }

 private:
  static double share(int64_t part, int64_t whole) { return whole ? double(part) / whole : 0; }
  double psnr(double squared_error) const;
};

// The oracle mask, (H, W) bool: where the internal image is closer to the truth than the external
// one (mean absolute difference over the channels). Images (C, H, W) float.
torch::Tensor oracle_mask(const torch::Tensor& internal_image, const torch::Tensor& external_image,
                          const torch::Tensor& truth);

// Counts of one view; all three images (C, H, W) float in [0, 1].
MaskCounts mask_counts(const torch::Tensor& internal_image, const torch::Tensor& external_image,
                       const torch::Tensor& truth, double threshold);

}  // namespace iesrgs::eval
