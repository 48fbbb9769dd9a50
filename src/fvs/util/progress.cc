#include "fvs/util/progress.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace fvs {

Progress::Progress(std::string label, int64_t total)
    : label_(std::move(label)), total_(total) {
  tty_ = ::isatty(STDERR_FILENO) == 1;
  const char* quiet = std::getenv("FVS_QUIET");
  quiet_ = quiet != nullptr && quiet[0] == '1';
  start_ = last_print_ = std::chrono::steady_clock::now();
}

Progress::~Progress() { Finish(); }

double Progress::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::Advance(int64_t n) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += n;
  Print(false);
}

void Progress::Set(int64_t done) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = done;
  Print(false);
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  Print(true);
}

void Progress::Print(bool final_line) {
  if (quiet_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (total_ <= 0) {
    if (!final_line && std::chrono::duration<double>(now - last_print_).count() < 1.0) {
      return;
    }
    last_print_ = now;
    std::fprintf(stderr, "%s%s: %lld done, %.1f s%s", tty_ ? "\r" : "", label_.c_str(),
                 static_cast<long long>(done_), elapsed,
                 (final_line || !tty_) ? "\n" : "");
    std::fflush(stderr);
    return;
  }
  const double fraction =
      std::min(1.0, static_cast<double>(done_) / static_cast<double>(total_));
  const int percent = static_cast<int>(fraction * 100.0);
  if (final_line && !tty_ && percent == 100 && last_percent_printed_ == 100) {
    return;  // the 100% line is already in the log
  }
  if (!final_line) {
    if (tty_) {
      if (std::chrono::duration<double>(now - last_print_).count() < 0.1 &&
          percent == last_percent_printed_) {
        return;
      }
    } else if (percent / 10 == last_percent_printed_ / 10 && last_percent_printed_ >= 0) {
      return;  // Logs get a line per 10%.
    }
  }
  last_print_ = now;
  last_percent_printed_ = percent;
  const double eta = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  constexpr int kWidth = 30;
  std::string bar(kWidth, ' ');
  for (int i = 0; i < static_cast<int>(fraction * kWidth); ++i) bar[i] = '#';
  std::fprintf(stderr, "%s%s [%s] %3d%% %lld/%lld %.1f s, ETA %.1f s%s", tty_ ? "\r" : "",
               label_.c_str(), bar.c_str(), percent, static_cast<long long>(done_),
               static_cast<long long>(total_), elapsed, eta,
               (final_line || !tty_) ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace fvs
