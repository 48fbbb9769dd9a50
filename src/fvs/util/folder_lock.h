// One writer per folder: a process that writes a workspace (prepare, stereo, mesher,
// source depths, fine-tuning) or an output folder (render, eval, pack, train) holds an
// exclusive open-file-description lock (fcntl F_OFD_SETLK: like flock(2), and it also
// holds on NFS) on `<folder>/.colmap-fvs.lock` while it runs, and the file names the
// holder (command, process id, host, since when). A second writer stops at once with one
// line naming the holder; readers (the GUI looking, eval or render into another folder)
// take no lock and go on.
//
// A holder killed with SIGKILL leaves the file, but the kernel drops its lock with the
// process, so the next writer takes it over and rewrites the holder. Programs a holder
// starts inherit the lock: a killed command whose child (ffmpeg) still writes the folder
// still holds it. COLMAP children die with their parent (colmap_ext/runner.cc). The
// holder removes the file when it ends; the acquire checks that the file it locked is
// still the one at the path, so removing it under a waiting opener cannot hand out two
// locks. On filesystems without locks the command goes on unlocked after one warning.
#pragma once

#include <string>

namespace fvs {

class FolderLock {
 public:
  // Creates `folder` if missing, then takes the lock for `command` (e.g.
  // "view_synthesis_prepare"). A non-empty `shard` ("i/n", the --shard of a render or
  // eval array job) takes a lock of its own: shards write disjoint files of one folder.
  // Throws Error(folder, "cannot create the output folder:
  // ...") or Error(folder, "in use by colmap <command> (process <pid> ..., since ...);
  // ...") when another process holds it.
  FolderLock(const std::string& folder, const std::string& command,
             const std::string& shard = "");
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

  // The lock file's path, and whether this process holds it (false only where the
  // filesystem has no locks).
  const std::string& path() const { return path_; }
  bool held() const { return fd_ >= 0; }

  // The holder recorded in `folder`'s lock file while some process holds the lock, as
  // "colmap <command> (process <pid> on <host>, since <time>)"; empty when the folder
  // is free. Never throws (the GUI asks before showing a workspace).
  static std::string Holder(const std::string& folder);

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace fvs
