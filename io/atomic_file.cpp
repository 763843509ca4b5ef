#include "io/atomic_file.h"

#include <limits.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

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
    std::error_code error;
    fs::create_directories(parent, error);
    if (error) throw InputError(FileLoc{path}, "cannot create directory " + parent.string() + ": " + error.message());
  }
  // Registered before the file exists and unregistered only after it is gone, so that a signal at
  // any moment in between finds it.
  registry_slot_ = register_temp_path(temp_path_);
  stream_.open(temp_path_, std::ios::binary | std::ios::trunc);
  if (!stream_) {
    const int open_errno = errno;
    unregister_temp_path(registry_slot_);
    throw InputError(FileLoc{path}, std::string("cannot create file: ") + std::strerror(open_errno));
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  std::error_code ignored;
  fs::remove(temp_path_, ignored);
  unregister_temp_path(registry_slot_);
}

void AtomicFile::write(const void *data, size_t byte_count) {
  stream_.write(static_cast<const char *>(data), std::streamsize(byte_count));
}

void AtomicFile::commit() {
  stream_.flush();
  if (!stream_) throw InputError(FileLoc{path_}, "write failed (disk full or no permission?)");
  stream_.close();
  if (stream_.fail()) throw InputError(FileLoc{path_}, "closing the file failed");
  std::error_code error;
  fs::rename(temp_path_, path_, error);
  if (error) throw InputError(FileLoc{path_}, "cannot rename " + temp_path_ + " onto it: " + error.message());
  committed_ = true;
  unregister_temp_path(registry_slot_);
}

}  // namespace plume::io
