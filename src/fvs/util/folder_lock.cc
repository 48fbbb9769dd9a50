#include "fvs/util/folder_lock.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "fvs/util/error.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;

std::string LockFileName(const std::string& shard) {
  if (shard.empty()) return ".colmap-fvs.lock";
  std::string name = ".colmap-fvs.shard-";
  for (const char c : shard)
    name += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
  return name + ".lock";
}

struct flock WholeFile(short type) {
  struct flock lock;
  std::memset(&lock, 0, sizeof(lock));
  lock.l_type = type;
  lock.l_whence = SEEK_SET;
  return lock;  // l_start = l_len = 0: the whole file; l_pid must be 0 for OFD locks
}

std::string HostName() {
  char host[256] = {0};
  if (::gethostname(host, sizeof(host) - 1) != 0) return "?";
  return host;
}

std::string NowUtc() {
  const std::time_t now = std::time(nullptr);
  std::tm utc;
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S UTC", &utc);
  return text;
}

// The lock file holds four lines: command, pid, host, since.
std::string DescribeHolder(int fd) {
  char buffer[1024];
  const ssize_t n = ::pread(fd, buffer, sizeof(buffer) - 1, 0);
  if (n <= 0) return "another process (not recorded)";
  std::istringstream in(std::string(buffer, static_cast<size_t>(n)));
  std::string command, pid_text, host, since;
  std::getline(in, command);
  std::getline(in, pid_text);
  std::getline(in, host);
  std::getline(in, since);
  std::string holder = "colmap " + command + " (process " + pid_text;
  if (host != HostName()) holder += " on " + host;
  holder += ", since " + since + ")";
  const long pid = std::strtol(pid_text.c_str(), nullptr, 10);
  if (host == HostName() && pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 &&
      errno == ESRCH) {
    holder += ", which has ended while a program it started still runs";
  }
  return holder;
}

bool NoLocksHere(int error) {
  return error == ENOLCK || error == EOPNOTSUPP || error == ENOSYS || error == EINVAL;
}

bool SameFile(int fd, const std::string& path) {
  struct stat opened, named;
  return ::fstat(fd, &opened) == 0 && ::stat(path.c_str(), &named) == 0 &&
         opened.st_dev == named.st_dev && opened.st_ino == named.st_ino;
}

}  // namespace

FolderLock::FolderLock(const std::string& folder, const std::string& command,
                       const std::string& shard)
    : path_((fs::path(folder.empty() ? "." : folder) / LockFileName(shard)).string()) {
  std::error_code ec;
  fs::create_directories(folder.empty() ? "." : folder, ec);
  Require(!ec, folder, "cannot create the output folder: " + ec.message());
  // Retried only when the file was removed between our open and our lock (its holder
  // ended): the lock must be on the file that is at the path.
  for (int attempt = 0; attempt < 100; ++attempt) {
    // No O_CLOEXEC: programs this process starts hold the lock with it.
    const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT, 0644);
    if (fd < 0) {
      const int error = errno;
      // A folder nobody may write: the command's own first write reports it.
      if (error == EROFS || error == EACCES) return;
      throw Error(path_,
                  std::string("cannot open the lock file: ") + std::strerror(error));
    }
    struct flock lock = WholeFile(F_WRLCK);
    if (::fcntl(fd, F_OFD_SETLK, &lock) != 0) {
      const int error = errno;
      if (NoLocksHere(error)) {
        ::close(fd);
        std::cerr << "warning: " << folder << ": the filesystem has no file locks; "
                  << "a second writer of this folder would not be stopped\n";
        return;
      }
      const std::string holder = DescribeHolder(fd);
      ::close(fd);
      throw Error(folder, "in use by " + holder +
                              "; wait for it to end or stop it, then run this again");
    }
    if (!SameFile(fd, path_)) {
      ::close(fd);
      continue;
    }
    const std::string record = command + "\n" + std::to_string(::getpid()) + "\n" +
                               HostName() + "\n" + NowUtc() + "\n";
    // The record only names the holder: where it cannot be written (a full disk, a
    // file-size limit) the lock still holds, and a refused writer says so.
    if (::ftruncate(fd, 0) == 0 && ::pwrite(fd, record.data(), record.size(), 0) !=
                                       static_cast<ssize_t>(record.size())) {
      (void)!::ftruncate(fd, 0);  // a partial record would name a wrong holder
    }
    fd_ = fd;
    return;
  }
  throw Error(path_, "the lock file keeps being removed by other processes");
}

FolderLock::~FolderLock() {
  if (fd_ < 0) return;
  // Removed while still locked: a waiting opener then finds it is not at the path.
  ::unlink(path_.c_str());
  ::close(fd_);
}

std::string FolderLock::Holder(const std::string& folder) {
  const std::string path = (fs::path(folder) / LockFileName("")).string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return "";
  struct flock probe = WholeFile(F_WRLCK);
  std::string holder;
  if (::fcntl(fd, F_OFD_GETLK, &probe) == 0 && probe.l_type != F_UNLCK) {
    holder = DescribeHolder(fd);
  }
  ::close(fd);
  return holder;
}

}  // namespace fvs
