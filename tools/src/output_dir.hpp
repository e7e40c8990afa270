// Output directories that appear whole or not at all: everything is written under a temporary sibling
// directory which replaces the target only on commit(). An uncommitted directory is removed on
// destruction, so an error never leaves a partial output behind.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>

namespace trm::cli {

class OutputDir {
 public:
  // Refuses (std::runtime_error) to replace an existing non-empty directory that is not a previous trm
  // output (one holding report.json), and a target that exists but is not a directory.
  explicit OutputDir(const std::filesystem::path& target);
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  const std::filesystem::path& staging() const { return staging_; }
  std::filesystem::path file(const std::string& name) const { return staging_ / name; }
  const std::filesystem::path& target() const { return target_; }

  // Writes a PNG (RGB channel order in, converted for OpenCV); throws with the file name on failure.
  void write_png(const std::string& name, const cv::Mat& rgb) const;
  void write_text(const std::string& name, const std::string& text) const;

  // Moves the staging directory into place (replacing a previous trm output).
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

}  // namespace trm::cli
