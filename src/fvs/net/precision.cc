#include "fvs/net/precision.h"

#include <ATen/autocast_mode.h>
#include <torch/version.h>

#include "fvs/util/error.h"

// LibTorch 2.4 replaced the per-device functions (set_enabled for CUDA, set_cpu_enabled,
// set_autocast_cpu_dtype, ...) by ones taking the device type; the old ones are
// deprecated there and gone later.
#if TORCH_VERSION_MAJOR > 2 || (TORCH_VERSION_MAJOR == 2 && TORCH_VERSION_MINOR >= 4)
#define FVS_AUTOCAST_BY_DEVICE_TYPE 1
#else
#define FVS_AUTOCAST_BY_DEVICE_TYPE 0
#endif

namespace fvs {
namespace {

#if FVS_AUTOCAST_BY_DEVICE_TYPE
bool IsEnabled(torch::DeviceType t) { return at::autocast::is_autocast_enabled(t); }
void SetEnabled(torch::DeviceType t, bool on) { at::autocast::set_autocast_enabled(t, on); }
torch::ScalarType GetDtype(torch::DeviceType t) { return at::autocast::get_autocast_dtype(t); }
void SetDtype(torch::DeviceType t, torch::ScalarType d) { at::autocast::set_autocast_dtype(t, d); }
#else
bool IsEnabled(torch::DeviceType t) {
  return t == torch::kCUDA ? at::autocast::is_enabled() : at::autocast::is_cpu_enabled();
}
void SetEnabled(torch::DeviceType t, bool on) {
  if (t == torch::kCUDA) {
    at::autocast::set_enabled(on);
  } else {
    at::autocast::set_cpu_enabled(on);
  }
}
torch::ScalarType GetDtype(torch::DeviceType t) {
  return t == torch::kCUDA ? at::autocast::get_autocast_gpu_dtype()
                           : at::autocast::get_autocast_cpu_dtype();
}
void SetDtype(torch::DeviceType t, torch::ScalarType d) {
  if (t == torch::kCUDA) {
    at::autocast::set_autocast_gpu_dtype(d);
  } else {
    at::autocast::set_autocast_cpu_dtype(d);
  }
}
#endif

}  // namespace

torch::ScalarType PrecisionDtype(const std::string& name, const std::string& subject) {
  if (name == "fp32") return torch::kFloat32;
  if (name == "bf16") return torch::kBFloat16;
  if (name == "fp16") return torch::kHalf;
  throw Error(subject, "'" + name + "': must be fp32, bf16 or fp16");
}

AutocastGuard::AutocastGuard(const torch::Device& device, torch::ScalarType dtype) {
  if (dtype == torch::kFloat32) return;
  Require(device.is_cpu() || device.is_cuda(), "autocast",
          "only on the CPU or CUDA, not " + device.str());
  Require(dtype == torch::kBFloat16 || (dtype == torch::kHalf && device.is_cuda()),
          "autocast", "bf16 (CPU or CUDA) or fp16 (CUDA only)");
  type_ = device.type();
  was_enabled_ = IsEnabled(type_);
  old_dtype_ = GetDtype(type_);
  SetEnabled(type_, true);
  SetDtype(type_, dtype);
  at::autocast::increment_nesting();
  active_ = true;
}

AutocastGuard::~AutocastGuard() {
  if (!active_) return;
  // As torch.autocast's __exit__: the cache of weights cast for this scope goes with
  // its outermost level (it would otherwise hold a copy of every weight in dtype).
  if (at::autocast::decrement_nesting() == 0) at::autocast::clear_cache();
  SetEnabled(type_, was_enabled_);
  SetDtype(type_, old_dtype_);
}

bool AutocastEnabled(torch::DeviceType type) { return IsEnabled(type); }

}  // namespace fvs
