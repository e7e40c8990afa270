#include "output_dir.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fstream>
#include <random>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace trm::cli {

namespace {

bool is_replaceable(const fs::path& target) {
  std::error_code ec;
  if (!fs::exists(target, ec)) return true;
  if (!fs::is_directory(target, ec)) {
    throw std::runtime_error("output path '" + target.string() + "' exists and is not a directory");
  }
  if (fs::is_empty(target, ec) || fs::exists(target / "report.json", ec)) return true;
  throw std::runtime_error("output directory '" + target.string() +
                           "' exists, is not empty and holds no report.json (not a trm output); "
                           "refusing to replace it");
}

}  // namespace

OutputDir::OutputDir(const fs::path& target) : target_(fs::absolute(target).lexically_normal()) {
  if (target_.filename().empty()) target_ = target_.parent_path();
  is_replaceable(target_);
  const fs::path parent = target_.parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) throw std::runtime_error("cannot create '" + parent.string() + "': " + ec.message());
  std::random_device rd;
  for (int attempt = 0; attempt < 16; ++attempt) {
    // Built with append(): GCC 12 mis-reports operator+ chains on strings under -Wrestrict.
    std::string name = ".";
    name.append(target_.filename().string()).append(".partial-").append(std::to_string(rd() % 1000000));
    const fs::path candidate = parent / name;
    if (fs::create_directory(candidate, ec)) {
      staging_ = candidate;
      return;
    }
  }
  throw std::runtime_error("cannot create a staging directory next to '" + target_.string() + "'" +
                           (ec ? ": " + ec.message() : std::string()));
}

OutputDir::~OutputDir() {
  if (!committed_ && !staging_.empty()) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
}

void OutputDir::write_png(const std::string& name, const cv::Mat& rgb) const {
  cv::Mat bgr;
  if (rgb.channels() == 3) {
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  } else {
    bgr = rgb;
  }
  const fs::path path = file(name);
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), bgr);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot write '" + path.string() + "': " + e.what());
  }
  if (!ok) throw std::runtime_error("cannot write '" + path.string() + "'");
}

void OutputDir::write_text(const std::string& name, const std::string& text) const {
  const fs::path path = file(name);
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write '" + path.string() + "'");
}

void OutputDir::commit() {
  std::error_code ec;
  is_replaceable(target_);
  if (fs::exists(target_, ec)) {
    // Move the old output aside first so that a failed rename never loses both.
    const fs::path old = staging_.string() + ".old";
    fs::rename(target_, old, ec);
    if (ec) throw std::runtime_error("cannot replace '" + target_.string() + "': " + ec.message());
    fs::rename(staging_, target_, ec);
    if (ec) {
      std::error_code restore;
      fs::rename(old, target_, restore);
      throw std::runtime_error("cannot move output into '" + target_.string() + "': " + ec.message());
    }
    fs::remove_all(old, ec);
  } else {
    fs::rename(staging_, target_, ec);
    if (ec) throw std::runtime_error("cannot move output into '" + target_.string() + "': " + ec.message());
  }
  committed_ = true;
}

}  // namespace trm::cli
