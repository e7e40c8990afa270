// The one atomic-file writer: regular files or new names only, staging named with the PID, nothing left behind.
#include "trm/atomic_file.hpp"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace trm::io {
namespace {

class Scratch {
 public:
  Scratch() : path_(fs::temp_directory_path() / ("trm-atomic-" + std::to_string(std::random_device{}()))) {
    fs::create_directories(path_);
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(AtomicFile, ReplacesARegularFileAndLeavesNoStaging) {
  Scratch s;
  const fs::path target = s.path() / "a.txt";
  std::ofstream(target) << "old";
  {
    AtomicFile file(target);
    file.write(std::string_view("new"));
    EXPECT_EQ(slurp(target), "old");  // not before commit
    file.commit();
  }
  EXPECT_EQ(slurp(target), "new");
  {
    AtomicFile unfinished(s.path() / "b.txt");
    unfinished.write(std::string_view("half"));
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(s.path()), fs::directory_iterator()), 1);
}

TEST(AtomicFile, RefusesEverythingButARegularFileOrANewName) {
  Scratch s;
  ASSERT_EQ(::mkfifo((s.path() / "fifo").c_str(), 0644), 0);
  fs::create_directory(s.path() / "dir");
  std::ofstream(s.path() / "real") << "keep";
  fs::create_symlink("real", s.path() / "link");
  for (const char* name : {"fifo", "dir", "link", "missing/x"}) {
    const fs::path target = s.path() / name;
    const std::string message = error_of([&] { write_file_atomically(target, std::string_view("x")); });
    EXPECT_NE(message.find("cannot write '" + target.string() + "'"), std::string::npos) << name << ": " << message;
  }
  EXPECT_TRUE(fs::is_fifo(s.path() / "fifo"));
  EXPECT_TRUE(fs::is_symlink(s.path() / "link"));
  EXPECT_EQ(slurp(s.path() / "real"), "keep");
  EXPECT_EQ(std::distance(fs::directory_iterator(s.path()), fs::directory_iterator()), 4);
}

TEST(AtomicFile, StagingNamesCarryThePidAndStaleOnesOfDeadProcessesGo) {
  Scratch s;
  const fs::path target = s.path() / "t.bin";
  const std::string own = staging_sibling(target).filename().string();
  EXPECT_EQ(own.rfind(".t.bin.partial-" + std::to_string(::getpid()) + "-", 0), 0u) << own;

  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const fs::path stale = s.path() / (".t.bin.partial-" + std::to_string(dead) + "-3");
  const fs::path live = s.path() / (".t.bin.partial-1-0");  // init: alive
  const fs::path other = s.path() / (".u.bin.partial-" + std::to_string(dead) + "-3");  // another target's
  const fs::path odd = s.path() / ".t.bin.partial-x-3";
  for (const fs::path& p : {stale, live, other, odd}) std::ofstream(p) << "?";
  write_file_atomically(target, std::string_view("ok"));
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_TRUE(fs::exists(odd));
  EXPECT_EQ(slurp(target), "ok");
}

TEST(AtomicFile, MessagesInsideAStagingDirectoryNameItsTarget) {
  Scratch s;
  const fs::path staging = s.path() / ".out.partial-1-0", target = s.path() / "out";
  StagingGuard guard(staging, target, [](const fs::path& p) { fs::create_directory(p); });
  EXPECT_EQ(shown(staging / "report.json"), (target / "report.json").string());
  guard.reset();
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_EQ(shown(staging / "report.json"), (staging / "report.json").string());
}

}  // namespace
}  // namespace trm::io
