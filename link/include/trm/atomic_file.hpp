// The one way trm writes a file: whole or not at all, only onto a regular file or a new name, through a
// staging sibling that carries the writer's PID and is removed on SIGINT / SIGTERM / SIGHUP.
//
// Staging names are DIR/.NAME.partial-PID-N (files and output directories alike). A later write of the same
// target removes such entries whose PID is no longer alive (SIGKILL cannot be caught); nothing else is touched.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace trm::io {

// Throws std::runtime_error("cannot write 'TARGET': reason") unless TARGET is a regular file or a new name in
// an existing directory. Devices, FIFOs, sockets, directories and symbolic links are refused: renaming over
// them would replace the node (or the link) with a regular file.
void check_file_target(const std::filesystem::path& target);

// DIR/.NAME.partial-PID-N for a target DIR/NAME: unique to this process and call.
std::filesystem::path staging_sibling(const std::filesystem::path& target);

// Removes DIR/.NAME.partial-PID-N entries of this target whose process is gone (kill(PID, 0) fails with ESRCH).
void remove_stale_staging(const std::filesystem::path& target);

// The path as the user named it: inside a registered staging directory it is shown under that directory's
// target, so that messages never name a hidden staging path.
std::string shown(const std::filesystem::path& path);

// A staging path registered for removal when a handled signal ends the process (install_signal_cleanup).
class StagingGuard {
 public:
  StagingGuard() = default;
  // Runs create(staging) with the registry locked, so a signal never finds the path created but not registered.
  StagingGuard(std::filesystem::path staging, std::filesystem::path target,
               const std::function<void(const std::filesystem::path&)>& create);
  ~StagingGuard();  // removes whatever is at the staging path (recursively) and forgets it
  StagingGuard(StagingGuard&& other) noexcept;
  StagingGuard& operator=(StagingGuard&& other) noexcept;
  StagingGuard(const StagingGuard&) = delete;
  StagingGuard& operator=(const StagingGuard&) = delete;

  // Runs publish() (the rename into place) with the registry locked: a signal waits until it is done.
  void publish(const std::function<void()>& publish) const;
  void reset();    // what the destructor does
  void release();  // forgets the path without removing it
  const std::filesystem::path& path() const { return staging_; }

 private:
  std::filesystem::path staging_;
};

// Blocks SIGINT, SIGTERM and SIGHUP in the calling thread (and so in every thread it starts later) and starts a
// thread that waits for them, removes every registered staging path and exits with 128 + signal. Call it first
// thing in main. A signal ignored at start (nohup, a background job's SIGINT) stays ignored.
void install_signal_cleanup();

// A file written through a staging sibling and renamed onto the target by commit(). Destroying it uncommitted
// (an exception, an error) removes the staging file. Every error names the target and the reason.
class AtomicFile {
 public:
  explicit AtomicFile(const std::filesystem::path& target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  void write(std::span<const std::uint8_t> bytes);
  void write(std::string_view text);
  void commit();
  const std::filesystem::path& target() const { return target_; }
  // Where the bytes are until commit(), for a library that writes only to a file name: it must have written and
  // closed the file before commit().
  const std::filesystem::path& staging_path() const { return staging_.path(); }

 private:
  void flush();
  [[noreturn]] void fail(const std::string& what, int error);

  std::filesystem::path target_;
  StagingGuard staging_;
  int fd_ = -1;
  std::vector<std::uint8_t> buffer_;
  bool committed_ = false;
};

void write_file_atomically(const std::filesystem::path& target, std::span<const std::uint8_t> bytes);
void write_file_atomically(const std::filesystem::path& target, std::string_view text);

}  // namespace trm::io
