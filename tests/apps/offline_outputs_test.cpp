// dpc-demo --offline's outputs. Stopped by SIGINT, SIGTERM, SIGHUP or SIGPIPE while it renders, it
// exits with 128 + the signal's number after one line naming the signal, removes its
// temporary files and leaves an existing output untouched. The outputs of one run are all or
// nothing: a write that fails for one output (--ir-out beyond a file-size limit) leaves every
// other output (--offline) unwritten too. An output path that is a symbolic link keeps the
// link and writes the file it leads to. Each run is a child process (fork + exec).
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/output_file.h"
#include "testing/temp_dir.h"

namespace fs = std::filesystem;

namespace {

const std::string kDemo = std::string(DPC_BINARY_DIR) + "/apps/dpc-demo";
const std::string kScenes = std::string(DPC_SOURCE_DIR) + "/scenes";

/// Starts dpc-demo with `args`, stdout and stderr into `log`; `fileLimit` > 0 caps the size
/// of every file it writes (RLIMIT_FSIZE, SIGXFSZ ignored: a write then fails with EFBIG, as
/// on a full disk).
pid_t startDemo(const std::vector<std::string>& args, const fs::path& log, rlim_t fileLimit = 0) {
  std::vector<char*> argv{const_cast<char*>(kDemo.c_str())};
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    std::FILE* out = std::freopen(log.c_str(), "w", stdout);
    if (!out || ::dup2(::fileno(stdout), STDERR_FILENO) < 0) ::_exit(125);
    if (fileLimit > 0) {
      ::signal(SIGXFSZ, SIG_IGN);
      const rlimit limit{fileLimit, fileLimit};
      ::setrlimit(RLIMIT_FSIZE, &limit);
    }
    ::execv(argv[0], argv.data());
    ::_exit(126);
  }
  return child;
}

/// The child's exit status, or -signal if a signal ended it.
int waitFor(pid_t child) {
  int status = 0;
  if (::waitpid(child, &status, 0) != child) return -1000;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

/// True once a file whose name contains `part` exists in `dir` (polled every 20 ms, at most
/// two minutes: loading the hall takes a few seconds on a loaded machine).
bool waitForFile(const fs::path& dir, const std::string& part) {
  for (int i = 0; i < 6000; ++i) {
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().filename().string().find(part) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The lines of `text` that start with `prefix`.
int linesStarting(const std::string& text, const std::string& prefix) {
  std::istringstream in(text);
  int n = 0;
  for (std::string line; std::getline(in, line);) n += line.rfind(prefix, 0) == 0;
  return n;
}

std::vector<std::string> namesIn(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST_CASE("dpc-demo --offline: a stop signal mid-render removes its temporaries", "[signals]") {
  for (const auto& [signal, name] :
       {std::pair{SIGINT, "SIGINT"}, std::pair{SIGTERM, "SIGTERM"}, std::pair{SIGHUP, "SIGHUP"},
        std::pair{SIGPIPE, "SIGPIPE"}}) {  // SIGPIPE: `dpc-demo ... | head` once head exits
    INFO(name);
    const dpc::test::TempDir dir("dpc_stop_signals");
    const fs::path out = dir.path() / "out", log = dir.path() / "log.txt";
    fs::create_directory(out);
    std::ofstream(out / "render.wav") << "an earlier render\n";
    // Ten minutes of the hall: still rendering long after the temporaries appear.
    const pid_t child =
        startDemo({kScenes + "/hall.json", "--offline", (out / "render.wav").string(), "--ir-out",
                   (out / "ir.wav").string(), "--duration", "600", "--quiet"},
                  log);
    REQUIRE(child > 0);
    const bool rendering = waitForFile(out, ".tmp-");
    if (!rendering) ::kill(child, SIGKILL);
    REQUIRE(rendering);
    REQUIRE(::kill(child, signal) == 0);
    CHECK(waitFor(child) == 128 + signal);
    // One line about it; the earlier output intact, no temporary left, nothing else written.
    const std::string text = slurp(log);
    CHECK(text.find(std::string("dpc-demo: interrupted by ") + name + "\n") != std::string::npos);
    CHECK(linesStarting(text, "dpc-demo: ") == 1);  // (before it: notes and the workload warning)
    CHECK(slurp(out / "render.wav") == "an earlier render\n");
    CHECK(namesIn(out) == std::vector<std::string>{"render.wav"});
  }
}

TEST_CASE("dpc-demo --offline: one output failing leaves every output unwritten", "[signals]") {
  const dpc::test::TempDir dir("dpc_all_or_nothing");
  const fs::path log = dir.path() / "log.txt";
  // 0.5 s of stereo at 48 kHz is 192 kB; the hall's 2-channel IR is several times larger.
  const pid_t child = startDemo(
      {kScenes + "/hall.json", "--offline", (dir.path() / "render.wav").string(), "--ir-out",
       (dir.path() / "ir.wav").string(), "--er-out", (dir.path() / "er.csv").string(), "--duration",
       "0.5", "--quiet", "--output", "stereo", "--rays", "256"},
      log, 400 * 1024);
  REQUIRE(child > 0);
  CHECK(waitFor(child) == 1);
  const std::string text = slurp(log);
  INFO(text);
  CHECK(text.find("ir.wav: cannot write") != std::string::npos);
  CHECK(namesIn(dir.path()) == std::vector<std::string>{"log.txt"});
}

TEST_CASE("dpc-demo --offline to a symbolic link writes the file it leads to", "[signals]") {
  const dpc::test::TempDir dir("dpc_output_link");
  const fs::path target = dir.path() / "target.wav", link = dir.path() / "link.wav";
  std::ofstream(target) << "an earlier render\n";
  fs::create_symlink(target, link);
  const pid_t child = startDemo({kScenes + "/shoebox.json", "--offline", link.string(),
                                 "--duration", "0.2", "--quiet", "--rays", "256"},
                                dir.path() / "log.txt");
  REQUIRE(child > 0);
  CHECK(waitFor(child) == 0);
  CHECK(fs::is_symlink(link));
  CHECK(fs::file_size(target) > 1000);  // the render, not the earlier text
  CHECK(namesIn(dir.path()) == std::vector<std::string>{"link.wav", "log.txt", "target.wav"});
}

TEST_CASE("An output file never replaces a non-regular file, and follows dangling links",
          "[signals]") {
  // Every writer goes through TempOutputFile: renaming its temporary onto a FIFO, a folder or
  // (run as root) a device node would replace it.
  const dpc::test::TempDir dir("dpc_output_kinds");
  const fs::path fifo = dir.path() / "out.fifo", folder = dir.path() / "out.d";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  fs::create_directory(folder);
  for (const fs::path& p : {fifo, folder})
    CHECK_THROWS_WITH(dpc::TempOutputFile(p.string()),
                      Catch::Contains("exists and is not a regular file"));
  CHECK(fs::is_fifo(fifo));
  // A dangling link is written through (its target created), a loop of links refused.
  const fs::path link = dir.path() / "link.wav", loop = dir.path() / "loop.wav";
  fs::create_symlink("made.wav", link);
  fs::create_symlink("loop.wav", loop);
  dpc::TempOutputFile out(link.string());
  out.writeAll("x", 1);
  out.commit();
  CHECK(fs::is_symlink(link));
  CHECK(fs::file_size(dir.path() / "made.wav") == 1);
  CHECK_THROWS_WITH(dpc::TempOutputFile(loop.string()),
                    Catch::Contains("too many levels of symbolic links"));
  CHECK(fs::is_symlink(loop));
}
