// The folder lock (util/folder_lock.h) between two real processes: a forked child holds
// it, the parent is refused with the child's command and pid, and takes it over once the
// child is killed with SIGKILL.
#include "fvs/util/folder_lock.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "support/test_support.h"

namespace fvs::testing {
namespace {

namespace fs = std::filesystem;

// A child process that holds `folder`'s lock for `command` until killed. Returns its pid
// once it holds the lock.
pid_t StartHolder(const std::string& folder, const std::string& command) {
  int ready[2];
  if (::pipe(ready) != 0) return -1;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(ready[0]);
    try {
      const FolderLock lock(folder, command);
      const char ok = 1;
      if (::write(ready[1], &ok, 1) != 1) ::_exit(2);
      while (true) ::pause();
    } catch (...) {
      ::_exit(3);
    }
  }
  ::close(ready[1]);
  char ok = 0;
  const bool held = ::read(ready[0], &ok, 1) == 1 && ok == 1;
  ::close(ready[0]);
  if (!held && pid > 0) ::waitpid(pid, nullptr, 0);
  return held ? pid : -1;
}

void Kill(pid_t pid) {
  ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
}

TEST(FolderLock, ASecondProcessIsRefusedWithTheHolderAndTakesOverAfterAKill) {
  TempDir dir;
  const std::string w = dir / "W";
  const pid_t holder = StartHolder(w, "view_synthesis_prepare");
  ASSERT_GT(holder, 0);
  const std::string pid = std::to_string(holder);
  EXPECT_NE(FolderLock::Holder(w).find("colmap view_synthesis_prepare (process " + pid),
            std::string::npos)
      << FolderLock::Holder(w);
  ExpectError([&] { FolderLock lock(w, "view_synthesis_mesher"); },
              {w, "in use by colmap view_synthesis_prepare (process " + pid + ", since ",
               " UTC)", "wait for it to end"});

  Kill(holder);  // SIGKILL: the lock file stays, the kernel drops the lock
  EXPECT_TRUE(fs::exists(w + "/.colmap-fvs.lock"));
  EXPECT_EQ(FolderLock::Holder(w), "");
  {
    const FolderLock lock(w, "view_synthesis_mesher");
    EXPECT_TRUE(lock.held());
    EXPECT_EQ(
        ReadTextFile(lock.path())
            .rfind("view_synthesis_mesher\n" + std::to_string(::getpid()) + "\n", 0),
        0u);
  }
  EXPECT_FALSE(fs::exists(w + "/.colmap-fvs.lock")) << "removed when released";
}

TEST(FolderLock, ShardsLockApartAndTheWholeFolderIsNotAShard) {
  TempDir dir;
  const FolderLock first(dir.path(), "view_synthesis", "0/2");
  const FolderLock second(dir.path(), "view_synthesis", "1/2");
  ExpectError([&] { FolderLock again(dir.path(), "view_synthesis", "1/2"); },
              {"in use by colmap view_synthesis"});
  const FolderLock whole(dir.path(), "view_synthesis_eval");
  EXPECT_TRUE(first.held() && second.held() && whole.held());
}

TEST(FolderLock, CreatesTheFolderOrSaysWhyItCannot) {
  TempDir dir;
  { const FolderLock lock(dir / "a/b", "view_synthesis"); }
  EXPECT_TRUE(fs::is_directory(dir / "a/b"));
  EXPECT_TRUE(fs::is_empty(dir / "a/b"));
  WriteTextFile(dir / "F", "a file\n");
  ExpectError([&] { FolderLock lock(dir / "F/O", "view_synthesis"); },
              {dir / "F/O", "cannot create the output folder"});
  EXPECT_EQ(FolderLock::Holder(dir / "nowhere"), "");
}

}  // namespace
}  // namespace fvs::testing
