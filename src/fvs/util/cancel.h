// Cooperative cancellation of a computation running on a thread (the GUI's live view
// drops a sharpening render the moment the camera moves again). While a CancelScope is
// alive on a thread, every ParallelFor / ParallelForRanges started from it (and from the
// threads those start) throws fvs::Cancelled at its next index once the flag is set, so a
// render stops within one row of work instead of running to its end. Without a scope
// nothing changes: the check is one null pointer test per index.
#pragma once

#include <atomic>
#include <stdexcept>

namespace fvs {

// Not an fvs::Error: nothing went wrong, and handlers that report errors to the user
// must not catch it as one.
class Cancelled : public std::exception {
 public:
  const char* what() const noexcept override { return "cancelled"; }
};

class CancelScope {
 public:
  // `flag` must outlive the scope; nullptr clears any outer scope for its lifetime.
  explicit CancelScope(const std::atomic<bool>* flag);
  ~CancelScope();
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

 private:
  const std::atomic<bool>* previous_;
};

// The flag of the innermost scope on this thread, nullptr when there is none.
const std::atomic<bool>* CurrentCancelFlag();

// Throws Cancelled when `flag` is set (nullptr: never).
inline void ThrowIfCancelled(const std::atomic<bool>* flag) {
  if (flag != nullptr && flag->load(std::memory_order_relaxed)) throw Cancelled();
}

}  // namespace fvs
