// Network precisions by name (fp32, bf16, fp16) and an RAII scope of LibTorch's automatic
// mixed precision (autocast), for the renderer, the trainer and its render benchmark.
#pragma once

#include <torch/torch.h>

#include <string>

namespace fvs {

// fp32 -> kFloat32, bf16 -> kBFloat16, fp16 -> kHalf; throws fvs::Error(subject, ...)
// for any other name.
torch::ScalarType PrecisionDtype(const std::string& name,
                                 const std::string& subject = "--precision");

// Autocast on `device` to `dtype` for the guard's lifetime (kFloat32: off, a no-op
// scope), as torch.autocast: matrix products and convolutions run in dtype, reductions
// and the ops autocast keeps in fp32 in fp32; the parameters stay what they are (fp32
// master weights) and gradients flow back through the casts to them. The destructor
// restores the previous state (enabled flag and dtype of that device) and clears
// autocast's cache of cast weights when the outermost scope ends. Works with the
// LibTorch API before 2.4 (set_cpu_enabled, set_autocast_cpu_dtype, ...) and after
// (set_autocast_enabled(device_type, ...)). Not copyable; one thread's state (autocast
// state is thread-local).
class AutocastGuard {
 public:
  AutocastGuard(const torch::Device& device, torch::ScalarType dtype);
  ~AutocastGuard();
  AutocastGuard(const AutocastGuard&) = delete;
  AutocastGuard& operator=(const AutocastGuard&) = delete;

  bool active() const { return active_; }

 private:
  bool active_ = false;
  torch::DeviceType type_ = torch::kCPU;
  bool was_enabled_ = false;
  torch::ScalarType old_dtype_ = torch::kFloat32;
};

// Whether autocast is on for this device type in this thread (tests).
bool AutocastEnabled(torch::DeviceType type);

}  // namespace fvs
