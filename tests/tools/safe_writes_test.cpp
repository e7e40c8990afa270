// Through the real `trm`: outputs go only onto regular files, new names or directories trm wrote; errors and
// signals leave nothing behind; stale staging entries of dead processes are removed (trm/atomic_file.hpp).
#include "trm_process.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <spawn.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace fs = std::filesystem;

namespace {

using trm::test::run_trm;
using trm::test::TrmResult;

class SafeWritesTempDir : public trm::test::ScratchDir {
 public:
  SafeWritesTempDir() : ScratchDir("trm-safe-") {}
};

// Every entry under dir (not following links): relative name -> type and, for files, the content.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> entries;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
    const fs::file_status status = it->symlink_status();
    std::string value = std::to_string(static_cast<int>(status.type()));
    if (fs::is_regular_file(status)) {
      std::ifstream in(it->path(), std::ios::binary);
      std::ostringstream text;
      text << in.rdbuf();
      // Size and hash, not the bytes: a failure message stays readable.
      value.append(":").append(std::to_string(text.str().size())).append(":").append(
          std::to_string(std::hash<std::string>{}(text.str())));
    } else if (fs::is_symlink(status)) {
      value.append("->").append(fs::read_symlink(it->path()).string());
    }
    entries[it->path().lexically_relative(dir).string()] = value;
  }
  return entries;
}

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// A failed command: exit code 1..127 and exactly one "trm: error:" line, which names `needle`.
void expect_one_error(const TrmResult& r, const std::string& needle, const std::string& what) {
  EXPECT_GE(r.exit_code, 1) << what << "\n" << r.output;
  EXPECT_LE(r.exit_code, 127) << what << "\n" << r.output;
  int errors = 0;
  std::istringstream lines(r.output);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("trm: error:") == std::string::npos) continue;
    ++errors;
    EXPECT_NE(line.find(needle), std::string::npos) << what << ": the error does not name " << needle << "\n" << line;
    EXPECT_EQ(line.find(".partial-"), std::string::npos) << what << ": the error names a staging path\n" << line;
  }
  EXPECT_EQ(errors, 1) << what << "\n" << r.output;
}

const std::string kSmall = " --scene discs --size 16x12 --frames 2";

TEST(SafeWrites, FileOutputsRefuseDevicesFifosSymlinksAndDirectories) {
  SafeWritesTempDir tmp;
  const fs::path fifo = tmp.path() / "fifo", node = tmp.path() / "null", link = tmp.path() / "link.json",
                 real = tmp.path() / "real.json", dir = tmp.path() / "dir";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const bool have_node = ::mknod(node.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0;  // a /dev/null of our own
  write_text(real, "keep me");
  fs::create_symlink("real.json", link);
  fs::create_directories(dir / "inside");
  write_text(dir / "inside" / "x.txt", "mine");

  std::vector<fs::path> targets = {fifo, link, dir};
  if (have_node) targets.push_back(node);
  const auto before = snapshot(tmp.path());
  for (const fs::path& target : targets) {
    const std::string t = target.string();
    const std::vector<std::string> commands = {
        "run" + kSmall + " --link dp1.2 --capture-out " + t + " --out " + tmp.str("new/sub/out"),
        "hw-report --size 16x12 --json " + t + " --out " + tmp.str("hw"),
        "vectors --update-golden " + t,
        "feed" + kSmall + " --fps 0 --file " + t,
        "feed" + kSmall + " --fps 0 --file " + tmp.str("rig.bin") + " --summary " + t,
    };
    for (const std::string& command : commands) {
      const TrmResult r = run_trm(command);
      expect_one_error(r, t, command);
      EXPECT_EQ(snapshot(tmp.path()), before) << command << ": something outside was created or changed";
    }
  }
  if (!have_node) GTEST_SKIP() << "mknod not permitted here: the device-node case was not run";
}

TEST(SafeWrites, OutDirIsReplacedOnlyIfTrmWroteEverythingInIt) {
  SafeWritesTempDir tmp;
  // A project that happens to hold a report.json is not a trm output.
  fs::create_directories(tmp.path() / "project");
  write_text(tmp.path() / "project" / "report.json", "{\"mine\": true}\n");
  write_text(tmp.path() / "project" / "main.cpp", "int main() {}\n");
  auto before = snapshot(tmp.path());
  for (const std::string& command :
       {"run" + kSmall + " --out " + tmp.str("project"), "hw-report --size 16x12 --out " + tmp.str("project"),
        "vectors" + kSmall + " --out " + tmp.str("project")}) {
    expect_one_error(run_trm(command), tmp.str("project"), command);
    EXPECT_EQ(snapshot(tmp.path()), before) << command;
  }

  // A previous trm output is replaced, and says so in its marker.
  const std::string run = "run" + kSmall + " --out " + tmp.str("out");
  ASSERT_EQ(run_trm(run).exit_code, 0);
  std::ifstream in(tmp.path() / "out" / ".trm-output.json");
  const nlohmann::json marker = nlohmann::json::parse(in);
  EXPECT_EQ(marker["tool"], "trm");
  EXPECT_EQ(marker["format"], "trm-output-1");
  EXPECT_NE(std::find(marker["files"].begin(), marker["files"].end(), "report.json"), marker["files"].end());
  ASSERT_EQ(run_trm(run).exit_code, 0);

  // ... but not once it also holds a file trm did not write.
  write_text(tmp.path() / "out" / "notes.txt", "my notes");
  before = snapshot(tmp.path());
  const TrmResult r = run_trm(run);
  expect_one_error(r, "notes.txt", run);
  EXPECT_EQ(snapshot(tmp.path()), before);

  // A symbolic link to a trm output is refused too (the link would be replaced by a directory).
  fs::remove(tmp.path() / "out" / "notes.txt");
  fs::create_directory_symlink("out", tmp.path() / "alias");
  before = snapshot(tmp.path());
  expect_one_error(run_trm("run" + kSmall + " --out " + tmp.str("alias")), tmp.str("alias"), "run --out alias");
  EXPECT_EQ(snapshot(tmp.path()), before);
}

TEST(SafeWrites, FeedSummaryInAMissingDirectoryIsAnErrorAndWritesNothing) {
  SafeWritesTempDir tmp;
  const std::string summary = tmp.str("missing/s.json");
  const TrmResult r = run_trm("feed" + kSmall + " --fps 0 --file " + tmp.str("rig.bin") + " --summary " + summary);
  expect_one_error(r, summary, "feed --summary missing/s.json");
  EXPECT_TRUE(fs::is_empty(tmp.path()));
}

TEST(SafeWrites, FileOutputsAtAnExistingDirectoryLeaveNoTemporary) {
  SafeWritesTempDir tmp;
  fs::create_directories(tmp.path() / "d");
  const auto before = snapshot(tmp.path());
  for (const std::string& command : {"hw-report --size 16x12 --json " + tmp.str("d"), "vectors --update-golden " + tmp.str("d")}) {
    expect_one_error(run_trm(command), tmp.str("d"), command);
    EXPECT_EQ(snapshot(tmp.path()), before) << command;
  }
}

TEST(SafeWrites, FeedFileIsNotCreatedWhenTheArgumentsOrTheFeedFail) {
  SafeWritesTempDir tmp;
  const std::string file = tmp.str("rig.bin");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"feed" + kSmall + " --fps nan --file " + file, "fps"},
      {"feed" + kSmall + " --fps 0 --roi 100,100,8,8 --file " + file, "100,100,8,8"},
      {"feed --capture " + tmp.str("none.trmcap") + " --fps 0 --file " + file, "none.trmcap"},
  };
  for (const auto& [command, needle] : cases) {
    expect_one_error(run_trm(command), needle, command);
    EXPECT_TRUE(fs::is_empty(tmp.path())) << command;
  }
  // The good case still writes it.
  ASSERT_EQ(run_trm("feed" + kSmall + " --fps 0 --file " + file).exit_code, 0);
  EXPECT_GT(fs::file_size(file), 2u * 16 * 12 * 3);
}

TEST(SafeWrites, VectorsUpdateGoldenWithOutIsAnError) {
  SafeWritesTempDir tmp;
  const TrmResult r = run_trm("vectors --update-golden " + tmp.str("g.txt") + " --out " + tmp.str("v"));
  expect_one_error(r, "--out", "vectors --update-golden --out");
  EXPECT_TRUE(fs::is_empty(tmp.path()));
}

// A 16 KiB tmpfs: a full disk without touching a real one. Needs mount rights (root); skipped elsewhere.
class FullDisk {
 public:
  explicit FullDisk(const fs::path& at) : at_(at) {
    fs::create_directories(at_);
    mounted_ = ::mount("tmpfs", at_.c_str(), "tmpfs", 0, "size=16k") == 0;
  }
  ~FullDisk() {
    if (mounted_) ::umount2(at_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }

 private:
  fs::path at_;
  bool mounted_ = false;
};

TEST(SafeWrites, AFullDiskNamesTheTargetAndTheReasonAndLeavesNothing) {
  SafeWritesTempDir tmp;
  FullDisk disk(tmp.path() / "disk");
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a small tmpfs here (needs root)";
  const fs::path d = tmp.path() / "disk";
  const std::string big = " --scene panorama --size 256x256 --frames 2";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run" + big + " --link dp1.2 --out " + (d / "out").string(), (d / "out").string()},
      {"feed" + big + " --fps 0 --file " + (d / "rig.bin").string(), (d / "rig.bin").string()},
      {"run" + big + " --link dp1.2 --capture-out " + (d / "c.trmcap").string() + " --out " + tmp.str("o"),
       (d / "c.trmcap").string()},
  };
  for (const auto& [command, target] : cases) {
    const TrmResult r = run_trm(command);
    expect_one_error(r, target, command);
    EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << command << "\n" << r.output;
    EXPECT_TRUE(fs::is_empty(d)) << command;
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "o"));
}

// Starts trm with the handled signals at their defaults (a test runner may have them ignored).
pid_t spawn_trm(const std::vector<std::string>& args, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&signals, s);
  posix_spawnattr_setsigdefault(&attr, &signals);
  sigemptyset(&signals);
  posix_spawnattr_setsigmask(&attr, &signals);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  std::vector<std::string> all = {TRM_EXECUTABLE};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, TRM_EXECUTABLE, &actions, &attr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  return pid;
}

bool holds_entry_with(const fs::path& dir, const std::string& part) {
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(part) != std::string::npos) return true;
  return false;
}

// Kills the process if the test ends (an assertion) before it was waited for.
struct Reaper {
  pid_t pid = -1;
  ~Reaper() {
    if (pid > 0 && ::kill(pid, SIGKILL) == 0) ::waitpid(pid, nullptr, 0);
  }
};

// Waits at most `seconds` for the process; kills it (and returns -1) if it is still running then.
int wait_for(pid_t pid, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

TEST(SafeWrites, SignalsDuringARunRemoveItsStagingEntries) {
  for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
    SafeWritesTempDir tmp, logs;
    const fs::path work = tmp.path();
    write_text(work / "keep.txt", "unrelated");
    const auto before = snapshot(work);
    const pid_t pid = spawn_trm({"run", "--scene", "discs", "--size", "32x24", "--frames", "200000", "--link", "dp1.2",
                                 "--capture-out", (work / "cap.trmcap").string(), "--out", (work / "out").string()},
                                logs.path() / "log");
    ASSERT_GT(pid, 0);
    Reaper reaper{pid};
    // Both staging entries (whatever their names) exist once the link has started.
    const auto started = [&] { return holds_entry_with(work, ".out.partial-") && holds_entry_with(work, "cap.trmcap"); };
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!started() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_TRUE(started());
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // well into the run
    ::kill(pid, signal);
    EXPECT_EQ(wait_for(pid, 30.0), 128 + signal) << "signal " << signal;
    reaper.pid = -1;
    EXPECT_EQ(snapshot(work), before) << "signal " << signal;
  }
}

TEST(SafeWrites, StaleStagingEntriesOfDeadProcessesAreRemoved) {
  SafeWritesTempDir tmp;
  const fs::path work = tmp.path();
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const std::string d = std::to_string(dead), live = std::to_string(::getpid());
  fs::create_directories(work / (".out.partial-" + d + "-0"));
  write_text(work / (".out.partial-" + d + "-0") / "report.json", "{}");
  write_text(work / (".cap.trmcap.partial-" + d + "-7"), "half a capture");
  fs::create_directories(work / (".out.partial-" + live + "-0"));  // a live writer's: not ours to remove
  write_text(work / ".out.partial-notes", "not trm's naming");
  write_text(work / ".hidden", "unrelated");
  const TrmResult r = run_trm("run" + kSmall + " --link dp1.2 --capture-out " + (work / "cap.trmcap").string() +
                              " --out " + (work / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(work / (".out.partial-" + d + "-0")));
  EXPECT_FALSE(fs::exists(work / (".cap.trmcap.partial-" + d + "-7")));
  EXPECT_TRUE(fs::is_directory(work / (".out.partial-" + live + "-0")));
  EXPECT_TRUE(fs::exists(work / ".out.partial-notes"));
  EXPECT_TRUE(fs::exists(work / ".hidden"));
  EXPECT_TRUE(fs::exists(work / "out" / "report.json"));
  EXPECT_TRUE(fs::exists(work / "cap.trmcap"));
}

}  // namespace
