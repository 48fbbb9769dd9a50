#include "fvs/util/cancel.h"

namespace fvs {
namespace {
thread_local const std::atomic<bool>* current_flag = nullptr;
}  // namespace

CancelScope::CancelScope(const std::atomic<bool>* flag) : previous_(current_flag) {
  current_flag = flag;
}

CancelScope::~CancelScope() { current_flag = previous_; }

const std::atomic<bool>* CurrentCancelFlag() { return current_flag; }

}  // namespace fvs
