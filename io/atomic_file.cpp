#include "io/atomic_file.h"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string_view>

#include "groom/error.h"

namespace plume::io {

namespace fs = std::filesystem;

namespace {

// The temporary paths of open AtomicFiles, kept where a signal handler can read them without
// allocating or locking. Each slot moves through these states; only the thread that moved a slot
// out of kFree writes its path, and a slot reaches kRemoving only from a signal handler, after which
// nobody writes it again, so a handler never reads a path that is being overwritten.
enum SlotState : int {
  kFree,      // unused: a constructor may claim it
  kFilling,   // claimed, path being copied: the temporary file does not exist yet
  kOpen,      // path complete: the handler may unlink it
  kRemoving,  // a handler is unlinking it: left alone by unregister_temp_path()
};

struct TempPathSlot {
  std::atomic<int> state{kFree};
  char path[PATH_MAX];
};

static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

constexpr int kRegistrySlotCount = 64;
std::array<TempPathSlot, kRegistrySlotCount> temp_path_registry;

/// Records `temp_path` before its file is created; returns the slot, or -1 if none is free or the
/// path does not fit (the file is then still written and removed normally, only not by a handler).
int register_temp_path(const std::string &temp_path) {
  if (temp_path.size() >= PATH_MAX) return -1;
  for (int i = 0; i < kRegistrySlotCount; ++i) {
    TempPathSlot &slot = temp_path_registry[size_t(i)];
    int expected = kFree;
    if (!slot.state.compare_exchange_strong(expected, kFilling, std::memory_order_acquire)) continue;
    std::memcpy(slot.path, temp_path.c_str(), temp_path.size() + 1);
    slot.state.store(kOpen, std::memory_order_release);
    return i;
  }
  return -1;
}

/// Frees the slot once its file is gone (renamed or removed), so that a handler has nothing to do.
void unregister_temp_path(int slot_index) {
  if (slot_index < 0) return;
  int expected = kOpen;
  temp_path_registry[size_t(slot_index)].state.compare_exchange_strong(expected, kFree, std::memory_order_acq_rel);
}

}  // namespace

void remove_open_temp_files() noexcept {
  for (TempPathSlot &slot : temp_path_registry) {
    int expected = kOpen;
    slot.state.compare_exchange_strong(expected, kRemoving, std::memory_order_acq_rel);
    // kRemoving may also come from a handler running on another thread for another signal: both
    // unlink it (twice is harmless), so whichever ends the process first has removed every file.
    if (slot.state.load(std::memory_order_acquire) == kRemoving) ::unlink(slot.path);
  }
}

AtomicFile::AtomicFile(const std::string &path)
    : path_(path), temp_path_(path + ".tmp-" + std::to_string(long(::getpid()))) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) {
    // The folders missing now are the ones this file makes, and removes again if it leaves them empty.
    std::error_code error;
    std::vector<std::string> missing;
    for (fs::path folder = parent; !folder.empty() && !fs::exists(folder, error); folder = folder.parent_path()) {
      missing.push_back(folder.string());
      if (folder.parent_path() == folder) break;
    }
    made_directories_.assign(missing.rbegin(), missing.rend());
    fs::create_directories(parent, error);
    if (error) {
      const std::string message = "cannot create directory " + parent.string() + ": " + error.message();
      remove_made_directories();
      throw InputError(FileLoc{path}, message);
    }
  }
  // Registered before the file exists and unregistered only after it is gone, so that a signal at
  // any moment in between finds it.
  registry_slot_ = register_temp_path(temp_path_);
  for (int attempt = 0;; ++attempt) {
    fd_ = ::open(temp_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0) {
      const int open_errno = errno;
      unregister_temp_path(registry_slot_);
      remove_made_directories();
      throw InputError(FileLoc{path}, std::string("cannot create file: ") + std::strerror(open_errno));
    }
    // The lock marks the file as a live writer's for as long as it has its temporary name. A
    // file system without locks gives none, and then no cleaner can prove the file stale either.
    // A cleaner may have removed a stale file of this name between open() and the lock (a dead
    // process of the same id on another machine): then the file is made again.
    while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
    }
    struct stat status;
    if (attempt >= 2 || ::fstat(fd_, &status) != 0 || status.st_nlink > 0) break;
    ::close(fd_);
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  ::unlink(temp_path_.c_str());  // under the lock, then the lock goes with the descriptor
  ::close(fd_);
  unregister_temp_path(registry_slot_);
  remove_made_directories();
}

void AtomicFile::remove_made_directories() noexcept {
  std::error_code ignored;
  for (auto folder = made_directories_.rbegin(); folder != made_directories_.rend(); ++folder)
    if (!fs::remove(*folder, ignored)) break;  // not empty (another writer's file), or gone
  made_directories_.clear();
}

void AtomicFile::write(const void *data, size_t byte_count) {
  const char *bytes = static_cast<const char *>(data);
  while (byte_count > 0 && write_errno_ == 0) {
    const ssize_t written = ::write(fd_, bytes, byte_count);
    if (written <= 0) {
      if (written == 0) write_errno_ = EIO;
      else if (errno != EINTR) write_errno_ = errno;
      continue;
    }
    bytes += written;
    byte_count -= size_t(written);
  }
}

void AtomicFile::commit() {
  if (write_errno_ != 0) throw InputError(FileLoc{path_}, std::string("write failed: ") + std::strerror(write_errno_));
  // Renamed while still locked, so that no cleaner elsewhere takes it for a dead writer's; a
  // failure that only closing reports (a network file system's deferred write) removes the file.
  std::error_code error;
  fs::rename(temp_path_, path_, error);
  if (error) throw InputError(FileLoc{path_}, "cannot rename " + temp_path_ + " onto it: " + error.message());
  committed_ = true;
  unregister_temp_path(registry_slot_);
  if (::close(fd_) != 0) {
    const int close_errno = errno;
    ::unlink(path_.c_str());
    throw InputError(FileLoc{path_}, std::string("closing the file failed, file removed: ") + std::strerror(close_errno));
  }
}

namespace {

/// The process id of a temporary file's name `<name>.tmp-<pid>`, and where `.tmp-` starts; 0 when
/// the name is not one.
long temp_name_pid(const std::string &name, size_t &r_suffix_at) {
  r_suffix_at = name.rfind(".tmp-");
  if (r_suffix_at == std::string::npos || r_suffix_at == 0) return 0;
  const std::string_view digits = std::string_view(name).substr(r_suffix_at + 5);
  if (digits.empty() || digits.size() > kMaxTempSuffixBytes - 5 || digits.front() == '0') return 0;
  long pid = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return 0;
    pid = pid * 10 + (c - '0');
  }
  return pid;
}

}  // namespace

std::vector<std::string> remove_stale_temp_files(const std::string &folder,
                                                 const std::function<bool(const std::string &name)> &is_output_name) {
  std::vector<std::string> removed;
  std::error_code error;
  const fs::path dir = folder.empty() ? fs::path(".") : fs::path(folder);
  fs::directory_iterator entries(dir, error);
  if (error) return removed;
  const long own_pid = long(::getpid());
  for (const fs::directory_entry &entry : entries) {
    const std::string name = entry.path().filename().string();
    size_t suffix_at = 0;
    const long pid = temp_name_pid(name, suffix_at);
    if (pid <= 0 || pid == own_pid || !is_output_name(name.substr(0, suffix_at))) continue;
    // Alive on this machine (or not ours to signal): its writer may still commit it.
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;
    const std::string path = entry.path().string();
    const int fd = ::open(path.c_str(), O_RDWR | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) continue;
    struct stat opened, named;
    // Locked: a writer elsewhere holds it. Unlocked and still under that name: stale.
    if (::fstat(fd, &opened) == 0 && S_ISREG(opened.st_mode) && ::flock(fd, LOCK_EX | LOCK_NB) == 0 &&
        ::lstat(path.c_str(), &named) == 0 && named.st_dev == opened.st_dev && named.st_ino == opened.st_ino &&
        ::unlink(path.c_str()) == 0)
      removed.push_back(path);
    ::close(fd);
  }
  return removed;
}

}  // namespace plume::io
