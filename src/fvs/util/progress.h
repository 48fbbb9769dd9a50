// Progress for long stages on stderr: a redrawn bar on a terminal, a line every few
// percent otherwise (logs, CI), so a user always sees what runs and how far it is.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace fvs {

class Progress {
 public:
  // total <= 0: unknown length (counts only). FVS_QUIET=1 silences all progress output.
  Progress(std::string label, int64_t total);
  ~Progress();

  // Thread-safe.
  void Advance(int64_t n = 1);
  void Set(int64_t done);
  void Finish();

  double ElapsedSeconds() const;

 private:
  void Print(bool final_line);

  std::string label_;
  int64_t total_;
  int64_t done_ = 0;
  int last_percent_printed_ = -1;
  bool finished_ = false;
  bool tty_ = false;
  bool quiet_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_print_;
  std::mutex mutex_;
};

// Wall-clock timer for the "numbers come with their cost" reports.
class Timer {
 public:
  Timer() : start_(std::chrono::steady_clock::now()) {}
  void Restart() { start_ = std::chrono::steady_clock::now(); }
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_)
        .count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace fvs
