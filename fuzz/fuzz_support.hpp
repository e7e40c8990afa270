// Shared by the libFuzzer targets: the finding rule (abort on a broken invariant or on an exception
// outside the error contract) and a private scratch directory for targets that must go through a file.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <typeinfo>

namespace trm::fuzz {

// A broken invariant: abort, so libFuzzer keeps the input as a crash artifact.
inline void check(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
    std::abort();
  }
}

// An exception the error contract does not allow (the parser must throw its documented type with a
// message): report what escaped and abort.
[[noreturn]] inline void unexpected_exception(const char* target) {
  try {
    throw;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: unexpected exception %s: %s\n", target, typeid(e).name(), e.what());
  } catch (...) {
    std::fprintf(stderr, "%s: unexpected non-standard exception\n", target);
  }
  std::abort();
}

// A per-process directory under $TMPDIR. libFuzzer ends a run without the atexit handlers, so it is
// not removed here: fuzz/run.sh points TMPDIR at a directory of its own for each target and clears it.
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::filesystem::path d = std::filesystem::path(tmp && *tmp ? tmp : "/tmp") /
                              ("trm-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline std::filesystem::path write_scratch_file(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scratch_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  check(static_cast<bool>(out), "cannot write the scratch file");
  return path;
}

// Closes the descriptors still open on `path`. OpenCV 4.6's Radiance HDR decoder leaves its FILE open
// when a header is malformed (a leak LeakSanitizer does not report: glibc still lists the FILE); over a
// long run those would exhaust the descriptor limit and turn every later input into a false finding.
inline void close_leaked_descriptors(const std::filesystem::path& path) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd", ec)) {
    std::error_code link_ec;
    if (std::filesystem::read_symlink(entry.path(), link_ec) == path) {
      const int fd = std::atoi(entry.path().filename().c_str());
      if (fd > 2) ::close(fd);
    }
  }
}

}  // namespace trm::fuzz
