// Real inputs: image sequences (glob) and video files, delivered as linear-light RGB frames.
#include "scenes/scene_support.hpp"
#include "trm/media.hpp"
#include "trm/scene.hpp"

#include <opencv2/videoio.hpp>  // the CAP_* constants; the calls go through trm/media.hpp

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

namespace fs = std::filesystem;

// Shell-style match of a file name against a pattern with '*' (any run) and '?' (one character).
bool wildcard_match(const std::string& pattern, const std::string& name) {
  std::size_t p = 0, n = 0, star = std::string::npos, resume = 0;
  while (n < name.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == name[n])) {
      ++p;
      ++n;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      resume = n;
    } else if (star != std::string::npos) {
      p = star + 1;
      n = ++resume;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

std::vector<std::string> expand_glob(const std::string& pattern) {
  const fs::path path(pattern);
  const std::string file_pattern = path.filename().string();
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (dir.string().find_first_of("*?") != std::string::npos) {
    throw std::runtime_error("image sequence '" + pattern + "': wildcards are only supported in the file name");
  }
  if (file_pattern.empty()) throw std::runtime_error("image sequence '" + pattern + "': no file name pattern");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw std::runtime_error("image sequence '" + pattern + "': directory '" + dir.string() + "' does not exist");
  }
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory()) continue;
    if (wildcard_match(file_pattern, name)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  std::vector<std::string> files;
  files.reserve(names.size());
  for (const std::string& name : names) files.push_back((dir / name).string());
  return files;
}

class ImageSequenceSource final : public FrameSource {
 public:
  explicit ImageSequenceSource(const std::string& pattern) : pattern_(pattern), files_(expand_glob(pattern)) {
    if (files_.empty()) throw std::runtime_error("image sequence '" + pattern + "' matches no files");
    // Validate every file up front (readable, supported, finite in-range content, one size), so a run
    // does not fail half way through.
    for (const std::string& file : files_) {
      const cv::Mat frame = scene_support::load_linear_image(file);
      if (size_.empty()) {
        size_ = frame.size();
      } else if (frame.size() != size_) {
        throw std::runtime_error("image sequence '" + pattern + "': '" + file + "' is " + std::to_string(frame.cols) +
                                 "x" + std::to_string(frame.rows) + " but '" + files_.front() + "' is " +
                                 std::to_string(size_.width) + "x" + std::to_string(size_.height));
      }
    }
  }

  std::string name() const override { return pattern_; }
  int width() const override { return size_.width; }
  int height() const override { return size_.height; }
  std::optional<std::int64_t> frame_count() const override { return static_cast<std::int64_t>(files_.size()); }

  cv::Mat linear_frame(std::int64_t t) override {
    if (t < 0 || t >= static_cast<std::int64_t>(files_.size())) {
      throw std::out_of_range("image sequence '" + pattern_ + "' has " + std::to_string(files_.size()) +
                              " frames; frame " + std::to_string(t) + " requested");
    }
    const std::string& file = files_[static_cast<std::size_t>(t)];
    cv::Mat frame = scene_support::load_linear_image(file);
    if (frame.size() != size_) throw std::runtime_error("image '" + file + "' changed size since the sequence was opened");
    return frame;
  }

  Motion motion(std::int64_t) const override { return {}; }  // unknown for recorded content

 private:
  std::string pattern_;
  std::vector<std::string> files_;
  cv::Size size_;
};

class VideoSource final : public FrameSource {
 public:
  explicit VideoSource(const std::string& path) : path_(path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      throw std::runtime_error("--input '" + path + "' is a directory: give an image sequence glob such as '" +
                               (fs::path(path) / "*.png").string() + "' or a video file");
    }
    if (!fs::exists(path, ec)) throw std::runtime_error("--input: video file '" + path + "' does not exist");
    if (!fs::is_regular_file(path, ec)) throw std::runtime_error("--input: '" + path + "' is not a regular file");
    reopen();
    if (!capture_.read(current_bgr_) || current_bgr_.empty()) {
      throw std::runtime_error("video file '" + path + "' has no decodable frames");
    }
    size_ = current_bgr_.size();
    current_index_ = 0;
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    if (count >= 1.0) frame_count_ = static_cast<std::int64_t>(count);
  }

  std::string name() const override { return path_; }
  int width() const override { return size_.width; }
  int height() const override { return size_.height; }
  // The container's frame count; it can be approximate for some formats, so reads past it still work
  // until the decoder runs out.
  std::optional<std::int64_t> frame_count() const override { return frame_count_; }

  cv::Mat linear_frame(std::int64_t t) override {
    if (t < 0) throw std::out_of_range("video frame index must be >= 0");
    if (t < current_index_) {  // seeking is not frame-accurate in every backend: restart and skip
      reopen();
      current_index_ = -1;
    }
    while (current_index_ < t) {
      if (!capture_.read(current_bgr_) || current_bgr_.empty()) {
        throw std::runtime_error("video file '" + path_ + "': cannot read frame " + std::to_string(current_index_ + 1));
      }
      ++current_index_;
    }
    if (current_bgr_.size() != size_) {
      throw std::runtime_error("video file '" + path_ + "': frame " + std::to_string(t) + " changes size");
    }
    if (current_bgr_.channels() != 3 && current_bgr_.channels() != 1) {
      throw std::runtime_error("video file '" + path_ + "': unsupported channel count");
    }
    return scene_support::linear_from_bgr8(current_bgr_);
  }

  Motion motion(std::int64_t) const override { return {}; }

 private:
  void reopen() {
    capture_.release();
    // Files go to FFmpeg when it is built in: probing every backend (GStreamer, camera drivers) for a
    // file that FFmpeg rejects only adds noise and slow start-up.
    const int api = media::has_video_backend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
    if (!capture_.open(path_, api)) throw std::runtime_error("cannot open video file '" + path_ + "' (unsupported format or codec)");
  }

  std::string path_;
  media::VideoReader capture_;
  cv::Mat current_bgr_;
  std::int64_t current_index_ = -1;
  cv::Size size_;
  std::optional<std::int64_t> frame_count_;
};

}  // namespace

std::unique_ptr<FrameSource> open_image_sequence(const std::string& pattern) {
  return std::make_unique<ImageSequenceSource>(pattern);
}

std::unique_ptr<FrameSource> open_video(const std::string& path) { return std::make_unique<VideoSource>(path); }

}  // namespace trm
