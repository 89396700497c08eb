// `dispex extract --watch` end to end: the command runs as a child process while the test saves
// new versions of the sculpt and the base as tools do -- in place in chunks with pauses (a
// half-written file exists for a while), by renaming a finished file onto the target, and
// broken. Throughout, a thread reads the map whenever it exists: it must always be a complete,
// valid map, byte for byte a full extraction of one of the versions saved. After each save the
// map equals the full extraction of the new files; a broken save gets one error line and leaves
// the map; SIGINT ends the watch with exit 130 and no temporary file.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <stop_token>
#include <thread>

#include "../extract/e2e_support.h"
#include "dispex/ptex.h"
#include "dispex/verify.h"

extern char** environ;

namespace dispex {
namespace {

using testing::DataPath;
using testing::MatchWhole;
using testing::RunDispex;
using testing::SculptOptions;
using testing::Slurp;
using testing::TempDir;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr int kSettleMs = 400;

void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// The i-th of n consecutive parts of `text`.
std::string Part(const std::string& text, std::size_t i, std::size_t n) {
  return text.substr(i * text.size() / n, (i + 1) * text.size() / n - i * text.size() / n);
}

// `obj` with every vertex within `radius` of vertex `center` pushed along z by a bump of
// height `height` (a local edit: only the faces near it change).
std::string PushBump(const std::string& obj, int center, double radius, double height) {
  std::vector<std::string> lines;
  std::istringstream in(obj);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  auto position = [](const std::string& line) {
    std::array<double, 3> p{};
    std::istringstream(line.substr(2)) >> p[0] >> p[1] >> p[2];
    return p;
  };
  std::vector<std::size_t> vertices;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].rfind("v ", 0) == 0) vertices.push_back(i);
  }
  const auto c = position(lines[vertices.at(static_cast<std::size_t>(center))]);
  for (std::size_t i : vertices) {
    auto p = position(lines[i]);
    const double r = std::hypot(p[0] - c[0], p[1] - c[1], p[2] - c[2]);
    if (r >= radius) continue;
    p[2] += height * (1 + std::cos(M_PI * r / radius));
    char buffer[128];
    std::snprintf(buffer, sizeof buffer, "v %.9g %.9g %.9g", p[0], p[1], p[2]);
    lines[i] = buffer;
  }
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

// `dispex extract ... --watch` as a child, its stderr read line by line.
class Watcher {
 public:
  explicit Watcher(std::vector<std::string> args) {
    int fds[2];
    EXPECT_EQ(::pipe2(fds, O_CLOEXEC), 0);
    read_fd_ = fds[0];
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    args.insert(args.begin(), DISPEX_EXE);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    EXPECT_EQ(::posix_spawn(&pid_, DISPEX_EXE, &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
  }
  ~Watcher() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    ::close(read_fd_);
  }

  // The next line of stderr within `timeout`, or nothing (none came, or it ended).
  std::optional<std::string> NextLine(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const std::size_t end = buffer_.find('\n');
      if (end != std::string::npos) {
        std::string line = buffer_.substr(0, end);
        buffer_.erase(0, end + 1);
        all_ += line + "\n";
        return line;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      pollfd p{read_fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(std::max<std::int64_t>(left.count(), 0))) <= 0) {
        if (left.count() <= 0) return std::nullopt;
        continue;
      }
      char chunk[4096];
      const ssize_t n = ::read(read_fd_, chunk, sizeof chunk);
      if (n <= 0) return std::nullopt;
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }
  // The next line, which must match `pattern` (POSIX extended); its groups, the whole line first.
  std::vector<std::string> Expect(const std::string& pattern,
                                  std::chrono::milliseconds timeout = 20s) {
    const std::optional<std::string> line = NextLine(timeout);
    EXPECT_TRUE(line.has_value()) << "no line matching " << pattern << "; stderr so far:\n" << all_;
    if (!line) return {};
    last_ = *line;
    std::optional<std::vector<std::string>> m = MatchWhole(last_, pattern);
    EXPECT_TRUE(m) << "expected " << pattern << "\n     got " << last_;
    return m.value_or(std::vector<std::string>{});
  }
  int Interrupt() {
    ::kill(pid_, SIGINT);
    int status = 0;
    EXPECT_EQ(::waitpid(pid_, &status, 0), pid_);
    pid_ = -1;
    while (NextLine(0ms)) {
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  const std::string& all() const { return all_; }

 private:
  pid_t pid_ = -1;
  int read_fd_ = -1;
  std::string buffer_, all_, last_;
};

TEST(Watch, SavesAreExtractedAgainAndBrokenOnesLeaveTheMap) {
  const auto start = std::chrono::steady_clock::now();
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  // The versions the artist saves: a sculpt, a local edit of it, another sculpt, a moved base
  // vertex.
  auto make = [&](Pattern pattern, const std::string& name) {
    MakeSculptOptions o = SculptOptions(cage, dir / name, 2, pattern, 0.01);
    EXPECT_TRUE(MakeSculpt(o).ok());
    return Slurp(o.output_path);
  };
  const std::string sculpt_a = make(Pattern::kDetail, "a.obj");
  const std::string sculpt_b = PushBump(sculpt_a, 1000, 0.1, 0.01);
  const std::string sculpt_c = make(Pattern::kSmooth, "c.obj");
  const std::string base = Slurp(cage);
  const std::string moved_base = PushBump(base, 10, 1e-6, 0.005);  // vertex 10 alone
  ASSERT_NE(moved_base, base);

  // Their full extractions, from files of the same names (the map records them).
  auto full = [&](const std::string& base_text, const std::string& sculpt_text,
                  const std::string& name) {
    fs::create_directories(dir / name);
    WriteFile(dir / (name + "/base.obj"), base_text);
    WriteFile(dir / (name + "/sculpt.obj"), sculpt_text);
    const auto r =
        RunDispex("extract " + (dir / (name + "/base.obj")) + " " + (dir / (name + "/sculpt.obj")) +
                      " -o " + (dir / (name + "/map.ptx")) + " -q",
                  dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return Slurp(dir / (name + "/map.ptx"));
  };
  const std::string map_a = full(base, sculpt_a, "full_a");
  const std::string map_b = full(base, sculpt_b, "full_b");
  const std::string map_c = full(base, sculpt_c, "full_c");
  const std::string map_d = full(moved_base, sculpt_a, "full_d");
  ASSERT_EQ(std::set<std::string>({map_a, map_b, map_c, map_d}).size(), 4u);

  fs::create_directories(dir / "work");
  const std::string base_path = dir / "work/base.obj", sculpt_path = dir / "work/sculpt.obj";
  const std::string map_path = dir / "work/map.ptx", report_path = dir / "work/report.json";
  WriteFile(base_path, base);
  WriteFile(sculpt_path, sculpt_a);

  // Whenever the map exists it is complete and valid, and a full extraction of a version.
  std::atomic<int> looks{0};
  std::mutex mutex;
  std::vector<std::string> bad;
  std::jthread reader([&](std::stop_token token) {
    while (!token.stop_requested()) {
      std::this_thread::sleep_for(10ms);
      if (!fs::exists(map_path)) continue;  // never removed once written
      const std::string bytes = Slurp(map_path);
      auto map = ParsePtex(bytes, "map.ptx");
      Status valid = map.ok() ? map->Validate() : map.status();
      std::lock_guard lock(mutex);
      ++looks;
      if (!valid.ok()) {
        bad.push_back("invalid: " + valid.message());
      } else if (bytes != map_a && bytes != map_b && bytes != map_c && bytes != map_d) {
        bad.push_back("a map of no saved version (" + std::to_string(bytes.size()) + " bytes)");
      }
    }
  });

  Watcher w({"extract", base_path, sculpt_path, "-o", map_path, "--watch", "--watch-settle",
             std::to_string(kSettleMs), "--report", report_path});
  // At start: every face, then the watch.
  w.Expect(R"(dispex: 252 of 252 faces extracted \(no previous map\), .*map\.ptx written in .* s)");
  w.Expect(R"(dispex: watching .*base\.obj and .*sculpt\.obj for saves \(Ctrl-C to stop\))");
  EXPECT_TRUE(Slurp(map_path) == map_a) << "the map is not the full extraction of the save";

  // A local edit saved in place in four chunks by a writer that keeps the file open, pausing
  // longer than the settling time: still one round, once it is closed, of the faces near it.
  {
    std::ofstream out(sculpt_path, std::ios::binary | std::ios::trunc);
    for (std::size_t i = 0; i < 4; ++i) {
      out << Part(sculpt_b, i, 4);
      out.flush();
      std::this_thread::sleep_for(std::chrono::milliseconds(kSettleMs * 3 / 2));
    }
  }
  ASSERT_TRUE(Slurp(sculpt_path) == sculpt_b);
  auto m = w.Expect(R"(dispex: .*sculpt\.obj changed: ([0-9]+) of 252 faces extracted again )"
                    R"(\(sculpt\), .*map\.ptx written in .* s)");
  if (m.size() > 1) {
    EXPECT_GT(std::stoi(m[1]), 0);
    EXPECT_LT(std::stoi(m[1]), 126) << "a local edit extracts the faces near it only";
  }
  EXPECT_TRUE(Slurp(map_path) == map_b) << "the map is not the full extraction of the save";

  // Another sculpt written in place in chunks, each its own open and close, with pauses
  // shorter than the settling time: one round, of the complete file.
  for (std::size_t i = 0; i < 4; ++i) {
    std::ofstream out(sculpt_path, std::ios::binary | (i == 0 ? std::ios::trunc : std::ios::app));
    out << Part(sculpt_c, i, 4);
    out.close();
    std::this_thread::sleep_for(std::chrono::milliseconds(kSettleMs / 5));
  }
  ASSERT_TRUE(Slurp(sculpt_path) == sculpt_c);
  w.Expect(R"(dispex: .*sculpt\.obj changed: [0-9]+ of 252 faces extracted again \(sculpt\), .*)");
  EXPECT_TRUE(Slurp(map_path) == map_c) << "the map is not the full extraction of the save";

  // A broken save (cut short, then a face of vertices that do not exist): one error line, the
  // map left as it was.
  WriteFile(sculpt_path, sculpt_a.substr(0, sculpt_a.size() / 2) + "\nf 1 2 999999\n");
  w.Expect(R"(dispex: .*sculpt\.obj changed: not extracted, .*map\.ptx left as it was: .*)");
  EXPECT_TRUE(Slurp(map_path) == map_c) << "the map is not the full extraction of the save";

  // A save by rename (a temporary file renamed onto the sculpt) is noticed.
  WriteFile(sculpt_path + ".tmp", sculpt_a);
  fs::rename(sculpt_path + ".tmp", sculpt_path);
  w.Expect(R"(dispex: .*sculpt\.obj changed: [0-9]+ of 252 faces extracted again \(sculpt\), .*)");
  EXPECT_TRUE(Slurp(map_path) == map_a) << "the map is not the full extraction of the save";

  // The base is watched too.
  WriteFile(base_path + ".tmp", moved_base);
  fs::rename(base_path + ".tmp", base_path);
  w.Expect(R"(dispex: .*base\.obj changed: [0-9]+ of 252 faces extracted again \(base\), .*)");
  EXPECT_TRUE(Slurp(map_path) == map_d) << "the map is not the full extraction of the save";
  // The report is rewritten each round.
  const nlohmann::json report = nlohmann::json::parse(Slurp(report_path));
  EXPECT_EQ(report["incremental"]["redo_reason"], "base") << report.dump();

  // A save that changes nothing extracts nothing.
  WriteFile(sculpt_path, sculpt_a);
  w.Expect(R"(dispex: .*sculpt\.obj changed: .*map\.ptx is up to date .*)");
  EXPECT_FALSE(w.NextLine(std::chrono::milliseconds(kSettleMs * 2))) << w.all();

  // Ctrl-C: exit 130, the map as the last round left it, no temporary file.
  EXPECT_EQ(w.Interrupt(), 130) << w.all();
  EXPECT_NE(w.all().find("dispex: interrupted: stopped watching\n"), std::string::npos) << w.all();
  reader.request_stop();
  reader.join();
  EXPECT_TRUE(Slurp(map_path) == map_d) << "the map is not the full extraction of the save";
  for (const auto& entry : fs::directory_iterator(dir / "work")) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos)
        << "temporary file left: " << entry.path();
  }
  EXPECT_GT(looks.load(), 20) << "the map was hardly looked at";
  for (const std::string& b : bad) ADD_FAILURE() << "the map while watching: " << b;
  std::printf("the map looked at %d times; %.1f s\n", looks.load(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

TEST(Watch, InterruptedRoundLeavesTheMap) {
  // Ctrl-C while a round extracts: it stops within a face, the file at -o is left as it was.
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  MakeSculptOptions make = SculptOptions(cage, dir / "sculpt.obj", 3, Pattern::kDetail, 0.005);
  ASSERT_TRUE(MakeSculpt(make).ok());
  const std::string map_path = dir / "map.ptx", old_content = "an older file that must survive";
  WriteFile(map_path, old_content);
  // Rays at 128 samples a side: about a second on 2 cores.
  Watcher w({"extract", cage, make.output_path, "-o", map_path, "--watch", "--method", "rays",
             "--oversample", "128", "--progress-lines"});
  const auto m = w.Expect(R"(progress extract ([0-9]+)/252)");
  ASSERT_EQ(m.size(), 2u);
  ASSERT_LT(std::stoi(m[1]), 200) << "the round was nearly done: no interruption to test";
  const auto sent = std::chrono::steady_clock::now();
  EXPECT_EQ(w.Interrupt(), 130) << w.all();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  EXPECT_LT(seconds, 1.0) << "took " << seconds << " s to stop";
  EXPECT_NE(w.all().find("dispex: interrupted: stopped watching\n"), std::string::npos) << w.all();
  EXPECT_EQ(w.all().find("faces extracted"), std::string::npos) << w.all();
  EXPECT_EQ(Slurp(map_path), old_content);
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos)
        << "temporary file left: " << entry.path();
  }
}

TEST(Watch, RefusesWhatItCannotWatch) {
  TempDir dir;
  const std::string cage = DataPath("meshes/opensubdiv/catmark_cube.obj");
  const std::string run = "extract " + cage + " " + cage + " ";
  auto r = RunDispex(run + "-o " + (dir / "part.ptx") + " --watch --shard 1/2", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--watch re-extracts a whole map, not a --shard"), std::string::npos)
      << r.err;
  r = RunDispex(run + "--out-dir " + (dir / "maps") + " --watch", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--watch re-extracts one map (-o), not --out-dir/--manifest"),
            std::string::npos)
      << r.err;
  r = RunDispex(run + "-o " + (dir / "map.ptx") + " --watch-settle 100", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--watch"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "map.ptx"));
}

}  // namespace
}  // namespace dispex
