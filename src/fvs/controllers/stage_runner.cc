#include "fvs/controllers/stage_runner.h"

#include <filesystem>
#include <iostream>
#include <sstream>

#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {
namespace fs = std::filesystem;
namespace {

// FNV-1a: a stable digest for chaining fingerprints (std::hash is not stable across
// builds).
std::string Digest(const std::string& text) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  std::ostringstream s;
  s << std::hex << h;
  return s.str();
}

}  // namespace

void RemoveAll(const std::string& path) {
  std::error_code ec;
  fs::remove_all(path, ec);
}

void MoveIntoPlace(const std::string& from, const std::string& to) {
  std::error_code ec;
  const std::string old = to + ".old-fvs";
  RemoveAll(old);
  if (fs::exists(to, ec)) fs::rename(to, old, ec);
  fs::rename(from, to, ec);
  if (ec) throw Error(to, "cannot move stage output into place (" + ec.message() + ")");
  RemoveAll(old);
}

StageRunner::StageRunner(Manifest manifest, int total)
    : manifest_(std::move(manifest)), total_(total) {}

void StageRunner::Run(const std::string& name, const std::vector<std::string>& inputs,
                      const std::string& options, const std::vector<std::string>& outputs,
                      const std::function<void()>& run) {
  ++index_;
  const std::string fingerprint =
      Digest(previous_ + "\n" + Manifest::Fingerprint(inputs, options, manifest_.root()));
  previous_ = fingerprint;
  if (manifest_.IsUpToDate(name, fingerprint, outputs)) {
    std::cerr << "[" << index_ << "/" << total_ << "] " << name
              << ": up to date, skipped\n";
    return;
  }
  std::cerr << "[" << index_ << "/" << total_ << "] " << name << " ...\n";
  manifest_.Forget(name);
  manifest_.Save();
  Timer timer;
  run();
  const double seconds = timer.Seconds();
  manifest_.Record(name, fingerprint, outputs, seconds);
  manifest_.Save();
  std::cerr << "[" << index_ << "/" << total_ << "] " << name << ": done in " << seconds
            << " s\n";
}

}  // namespace fvs
