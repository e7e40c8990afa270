#include "output_dir.hpp"

#include "trm/media.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <fcntl.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;

namespace trm::cli {

namespace {

[[noreturn]] void refuse(const fs::path& target, const std::string& why) {
  throw std::runtime_error("output directory '" + target.string() + "' " + why +
                           "; refusing to replace it (remove it yourself or give another directory)");
}

// The manifest of a previous trm output, or nullopt when the marker is missing or not trm's.
std::optional<std::set<std::string>> manifest_of(const fs::path& dir) {
  const fs::path marker = dir / kOutputMarker;
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(marker, ec))) return std::nullopt;
  std::ifstream in(marker, std::ios::binary);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (!j.is_object() || j.value("tool", "") != "trm" || j.value("format", "") != kOutputFormat || !j.contains("files") ||
      !j["files"].is_array())
    return std::nullopt;
  std::set<std::string> files;
  for (const auto& f : j["files"]) {
    if (!f.is_string()) return std::nullopt;
    files.insert(f.get<std::string>());
  }
  return files;
}

// Throws unless the target is absent, an empty directory, or a trm output holding only what trm wrote there.
void check_replaceable(const fs::path& target) {
  struct stat st {};
  if (::lstat(target.c_str(), &st) != 0) {
    if (errno == ENOENT) return;
    throw std::runtime_error("cannot use output path '" + target.string() + "': " + std::strerror(errno));
  }
  if (S_ISLNK(st.st_mode))
    throw std::runtime_error("output path '" + target.string() +
                             "' is a symbolic link; give the directory it points to (trm does not replace links)");
  if (!S_ISDIR(st.st_mode))
    throw std::runtime_error("output path '" + target.string() + "' exists and is not a directory");
  std::error_code ec;
  if (fs::is_empty(target, ec)) return;
  const auto manifest = manifest_of(target);
  if (!manifest) refuse(target, "exists, is not empty and is not a trm output (no " + std::string(kOutputMarker) + ")");
  for (auto it = fs::recursive_directory_iterator(target, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().lexically_relative(target).generic_string();
    if (name == kOutputMarker) continue;
    const fs::file_status status = it->symlink_status(ec);
    bool ours = false;
    if (fs::is_directory(status)) {
      ours = std::any_of(manifest->begin(), manifest->end(),
                         [&](const std::string& f) { return f.rfind(name + "/", 0) == 0; });
    } else {
      ours = fs::is_regular_file(status) && manifest->count(name) > 0;
    }
    if (!ours) refuse(target, "holds '" + name + "', which trm did not write there");
  }
  if (ec) throw std::runtime_error("cannot read output directory '" + target.string() + "': " + ec.message());
}

std::vector<std::string> files_under(const fs::path& dir) {
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path().lexically_relative(dir).generic_string());
  std::sort(files.begin(), files.end());
  return files;
}

struct NameTaken {};

}  // namespace

OutputDir::OutputDir(const fs::path& target) : target_(fs::absolute(target).lexically_normal()) {
  if (target_.filename().empty()) target_ = target_.parent_path();
  check_replaceable(target_);
  const fs::path parent = target_.parent_path();
  std::error_code ec;
  for (fs::path p = parent; !p.empty() && p != p.root_path() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path())
    created_parents_.push_back(p);
  fs::create_directories(parent, ec);
  try {
    if (ec) throw std::runtime_error("cannot create '" + parent.string() + "': " + ec.message());
    io::remove_stale_staging(target_);
    for (int attempt = 0; staging_.path().empty(); ++attempt) {
      try {
        staging_ = io::StagingGuard(io::staging_sibling(target_), target_, [&](const fs::path& path) {
          if (fs::create_directory(path, ec)) return;
          if (!ec && attempt < 100) throw NameTaken{};  // a stale entry of an earlier process with our PID
          throw std::runtime_error("cannot create a staging directory next to '" + target_.string() + "': " +
                                   (ec ? ec.message() : std::string("name taken")));
        });
      } catch (const NameTaken&) {
      }
    }
  } catch (...) {
    remove_created_parents();
    throw;
  }
}

void OutputDir::remove_created_parents() const {
  std::error_code ignored;
  for (const fs::path& p : created_parents_) fs::remove(p, ignored);  // only while still empty
}

OutputDir::~OutputDir() {
  if (committed_) return;
  staging_.reset();
  remove_created_parents();
}

void OutputDir::write_png(const std::string& name, const cv::Mat& rgb) const {
  cv::Mat bgr;
  if (rgb.channels() == 3) {
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  } else {
    bgr = rgb;
  }
  std::vector<std::uint8_t> png;
  bool ok = false;
  try {
    ok = media::encode_image(".png", bgr, png);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot encode '" + (target_ / name).string() + "' as PNG: " + e.what());
  }
  if (!ok) throw std::runtime_error("cannot encode '" + (target_ / name).string() + "' as PNG");
  io::write_file_atomically(file(name), png);
}

void OutputDir::write_text(const std::string& name, const std::string& text) const {
  io::write_file_atomically(file(name), text);
}

void OutputDir::commit() {
  if (committed_) return;
  const nlohmann::json marker = {{"tool", "trm"}, {"format", kOutputFormat}, {"files", files_under(staging())}};
  write_text(kOutputMarker, marker.dump(2) + "\n");
  check_replaceable(target_);  // again: the target may have changed during the run
  struct stat st {};
  const bool replace = ::lstat(target_.c_str(), &st) == 0;
  int error = 0;
  staging_.publish([&] {
    // One atomic step where the kernel can: the old output lands at the staging name, removed below.
    const unsigned flags = replace ? RENAME_EXCHANGE : RENAME_NOREPLACE;
    if (::renameat2(AT_FDCWD, staging().c_str(), AT_FDCWD, target_.c_str(), flags) == 0) return;
    if (errno != EINVAL && errno != ENOSYS) {
      error = errno;
      return;
    }
    if (!replace) {
      if (::rename(staging().c_str(), target_.c_str()) != 0) error = errno;
      return;
    }
    // No RENAME_EXCHANGE on this file system: move the old output aside first so that a failed rename never
    // loses both.
    io::StagingGuard aside(io::staging_sibling(target_), target_, [&](const fs::path& path) {
      if (::rename(target_.c_str(), path.c_str()) != 0) error = errno;
    });
    if (error != 0) return;
    if (::rename(staging().c_str(), target_.c_str()) != 0) {
      error = errno;
      if (::rename(aside.path().c_str(), target_.c_str()) != 0) aside.release();  // keep the old output
    }
  });
  if (error != 0) throw std::runtime_error("cannot move output into '" + target_.string() + "': " + std::strerror(error));
  committed_ = true;
  staging_.reset();  // after an exchange: the previous output
}

}  // namespace trm::cli
