#include "trm/atomic_file.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <utility>

namespace fs = std::filesystem;

namespace trm::io {

namespace {

struct Entry {
  fs::path staging;
  fs::path target;
};

// Leaked on purpose: the signal thread may use it while static destructors run.
struct Registry {
  std::recursive_mutex mutex;
  std::vector<Entry> entries;
};

Registry& registry() {
  static Registry* r = new Registry;
  return *r;
}

bool is_registered(const fs::path& staging) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  // By name: it holds our PID and a counter, so it cannot belong to another directory's writer by chance.
  return std::any_of(r.entries.begin(), r.entries.end(),
                     [&](const Entry& e) { return e.staging.filename() == staging.filename(); });
}

// Whether dir is a staging directory of this process: fresh and private, so it holds nothing stale.
bool is_our_staging(const fs::path& dir) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  const fs::path d = dir.lexically_normal();
  return std::any_of(r.entries.begin(), r.entries.end(), [&](const Entry& e) { return e.staging.lexically_normal() == d; });
}

std::string reason(int error) { return std::strerror(error); }

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The PID in NAME if it is exactly ".<target name>.partial-PID-N", else 0.
pid_t staging_pid(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string rest = name.substr(prefix.size());
  const std::size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || dash + 1 == rest.size()) return 0;
  const auto digits = [](const std::string& s) { return std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; }); };
  const std::string pid = rest.substr(0, dash);
  if (!digits(pid) || !digits(rest.substr(dash + 1)) || pid.size() > 9) return 0;
  return static_cast<pid_t>(std::stol(pid));
}

bool process_is_gone(pid_t pid) { return ::kill(pid, 0) == -1 && errno == ESRCH; }

// Retried: a writer thread may still be creating files in a staging directory while it is removed.
void remove_fully(const fs::path& path) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::error_code ec;
    fs::remove_all(path, ec);
    if (!fs::exists(fs::symlink_status(path, ec))) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

[[noreturn]] void clean_up_and_exit(int signal) {
  Registry& r = registry();
  r.mutex.lock();  // never released: no staging path can be created or published from now on
  for (const Entry& e : r.entries) remove_fully(e.staging);
  const char* name = signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : "SIGHUP";
  const std::string message = std::string("\ntrm: interrupted by ") + name + "; partial outputs removed\n";
  [[maybe_unused]] const ssize_t ignored = ::write(STDERR_FILENO, message.data(), message.size());
  ::_exit(128 + signal);
}

}  // namespace

void check_file_target(const fs::path& target) {
  const auto refuse = [&](const std::string& why) {
    throw std::runtime_error("cannot write '" + shown(target) + "': " + why);
  };
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..") refuse("not a file name");
  struct stat st {};
  if (::lstat(target.c_str(), &st) == 0) {
    if (S_ISREG(st.st_mode)) return;
    refuse(std::string("it is ") + kind_of(st.st_mode) + "; trm writes only to a regular file or a new name");
  }
  if (errno != ENOENT) refuse(reason(errno));
  const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  if (::stat(parent.c_str(), &st) != 0) {
    const int error = errno;
    refuse("directory '" + shown(parent) + "': " + reason(error));
  }
  if (!S_ISDIR(st.st_mode)) refuse("'" + shown(parent) + "' is not a directory");
}

fs::path staging_sibling(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  // Built with append(): GCC 12 mis-reports operator+ chains on strings under -Wrestrict.
  std::string name = ".";
  name.append(target.filename().string())
      .append(".partial-")
      .append(std::to_string(::getpid()))
      .append("-")
      .append(std::to_string(counter++));
  return target.parent_path() / name;
}

void remove_stale_staging(const fs::path& target) {
  const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::string prefix = ".";
  prefix.append(target.filename().string()).append(".partial-");
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const pid_t pid = staging_pid(it->path().filename().string(), prefix);
    if (pid <= 0) continue;
    // One of ours that no StagingGuard holds is as stale as one of a dead process.
    const bool stale = pid == ::getpid() ? !is_registered(it->path()) : process_is_gone(pid);
    if (stale) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);
    }
  }
}

std::string shown(const fs::path& path) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  const std::string p = path.lexically_normal().string();
  for (const Entry& e : r.entries) {
    const std::string s = e.staging.lexically_normal().string();
    if (p == s) return e.target.string();
    if (p.size() > s.size() && p.compare(0, s.size(), s) == 0 && p[s.size()] == '/')
      return (e.target / p.substr(s.size() + 1)).string();
  }
  return path.string();
}

// ------------------------------------------------------------------------------------------- StagingGuard

StagingGuard::StagingGuard(fs::path staging, fs::path target, const std::function<void(const fs::path&)>& create) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  create(staging);
  r.entries.push_back({staging, std::move(target)});
  staging_ = std::move(staging);
}

StagingGuard::~StagingGuard() { reset(); }

StagingGuard::StagingGuard(StagingGuard&& other) noexcept : staging_(std::exchange(other.staging_, {})) {}

StagingGuard& StagingGuard::operator=(StagingGuard&& other) noexcept {
  if (this != &other) {
    reset();
    staging_ = std::exchange(other.staging_, {});
  }
  return *this;
}

void StagingGuard::publish(const std::function<void()>& publish) const {
  std::lock_guard lock(registry().mutex);
  publish();
}

void StagingGuard::reset() {
  if (staging_.empty()) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
  release();
}

void StagingGuard::release() {
  if (staging_.empty()) return;
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  std::erase_if(r.entries, [&](const Entry& e) { return e.staging == staging_; });
  staging_.clear();
}

void install_signal_cleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    sigset_t set;
    sigemptyset(&set);
    for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction current {};
      if (::sigaction(signal, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) continue;
      sigaddset(&set, signal);
    }
    if (::pthread_sigmask(SIG_BLOCK, &set, nullptr) != 0) return;
    std::thread([set] {
      int signal = 0;
      while (::sigwait(&set, &signal) != 0) {
      }
      clean_up_and_exit(signal);
    }).detach();
  });
}

// --------------------------------------------------------------------------------------------- AtomicFile

namespace {
struct NameTaken {};
constexpr std::size_t kBufferBytes = 1 << 20;
}  // namespace

AtomicFile::AtomicFile(const fs::path& target) : target_(target) {
  check_file_target(target_);
  if (!is_our_staging(target_.parent_path())) remove_stale_staging(target_);  // no scan per file of an output dir
  for (int attempt = 0;; ++attempt) {
    try {
      staging_ = StagingGuard(staging_sibling(target_), target_, [&](const fs::path& path) {
        fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd_ >= 0) return;
        const int error = errno;
        if (error == EEXIST && attempt < 100) throw NameTaken{};
        throw std::runtime_error("cannot write '" + shown(target_) + "': " + reason(error));
      });
      return;
    } catch (const NameTaken&) {
    }
  }
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
}

void AtomicFile::fail(const std::string& what, int error) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  staging_.reset();
  throw std::runtime_error("cannot " + what + " '" + shown(target_) + "': " + reason(error));
}

void AtomicFile::flush() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail("write", errno);
    done += static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void AtomicFile::write(std::span<const std::uint8_t> bytes) {
  if (fd_ < 0) throw std::logic_error("AtomicFile '" + target_.string() + "' is closed");
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
  if (buffer_.size() >= kBufferBytes) flush();
}

void AtomicFile::write(std::string_view text) {
  write(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

void AtomicFile::commit() {
  if (committed_) return;
  if (fd_ < 0) throw std::logic_error("AtomicFile '" + target_.string() + "' is closed");
  flush();
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) fail("write", errno);
  try {
    check_file_target(target_);  // again: the target may have changed while we wrote
  } catch (...) {
    staging_.reset();
    throw;
  }
  int error = 0;
  staging_.publish([&] {
    if (::rename(staging_.path().c_str(), target_.c_str()) != 0) error = errno;
  });
  if (error != 0) fail("write", error);
  committed_ = true;
  staging_.reset();
}

void write_file_atomically(const fs::path& target, std::span<const std::uint8_t> bytes) {
  AtomicFile file(target);
  file.write(bytes);
  file.commit();
}

void write_file_atomically(const fs::path& target, std::string_view text) {
  AtomicFile file(target);
  file.write(text);
  file.commit();
}

}  // namespace trm::io
