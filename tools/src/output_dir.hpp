// Output directories that appear whole or not at all: everything is written under a staging sibling
// directory (DIR/.NAME.partial-PID-N, removed on SIGINT / SIGTERM / SIGHUP, see trm/atomic_file.hpp) which
// replaces the target only on commit(). An uncommitted directory is removed on destruction, so an error never
// leaves a partial output behind.
//
// commit() adds the marker .trm-output.json: {"tool": "trm", "format": "trm-output-1", "files": [...]}, the
// manifest of every file trm wrote there. An existing target is replaced only if it is empty, or holds that
// marker and nothing that is not in its manifest: trm never deletes a file it did not write.
#pragma once

#include "trm/atomic_file.hpp"

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace trm::cli {

inline constexpr const char* kOutputMarker = ".trm-output.json";
inline constexpr const char* kOutputFormat = "trm-output-1";

class OutputDir {
 public:
  // Refuses (std::runtime_error) a target that is not a directory (a symbolic link included) and an existing
  // non-empty directory that is not a trm output as described above.
  explicit OutputDir(const std::filesystem::path& target);
  ~OutputDir();  // uncommitted: removes the staging directory and the parent directories it created
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  const std::filesystem::path& staging() const { return staging_.path(); }
  // A path in the staging directory, for writers of their own (which must go through io::AtomicFile).
  std::filesystem::path file(const std::string& name) const { return staging_.path() / name; }
  const std::filesystem::path& target() const { return target_; }

  // Writes a PNG (RGB channel order in, converted for OpenCV); throws with the file name on failure.
  void write_png(const std::string& name, const cv::Mat& rgb) const;
  void write_text(const std::string& name, const std::string& text) const;

  // Writes the marker and moves the staging directory into place (replacing a previous trm output).
  void commit();

 private:
  void remove_created_parents() const;

  std::filesystem::path target_;
  io::StagingGuard staging_;
  std::vector<std::filesystem::path> created_parents_;  // deepest first
  bool committed_ = false;
};

}  // namespace trm::cli
