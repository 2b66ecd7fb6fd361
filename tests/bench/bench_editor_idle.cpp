// Idle CPU of caliper-editor: runs the editor (a real window: start this under xvfb-run) with
// no input, waits until it has started, then reads its CPU time (utime + stime from
// /proc/PID/stat) once a second for a measuring window. Runs the baseline first: the same
// editor with --no-idle-wait (redraws every frame, as before the editor waited for events).
//
//   xvfb-run -a -s "-screen 0 1600x1000x24" build/bin/bench_editor_idle
//     [--warmup S] [--seconds S] [--baseline-seconds S] -- build/bin/caliper-editor ARGS...
//
// Prints per-run: median and mean CPU % of one core over the window's one-second samples.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

/// utime + stime of `pid` in clock ticks.
long long cpu_ticks(pid_t pid) {
  const std::string path = "/proc/" + std::to_string(pid) + "/stat";
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) throw std::runtime_error("cannot open " + path + " (did the editor exit?)");
  char buf[4096];
  const size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  const std::string text(buf, n);
  const auto close = text.rfind(')');
  if (close == std::string::npos) throw std::runtime_error("cannot read /proc/PID/stat");
  if (close + 2 < text.size() && (text[close + 2] == 'Z' || text[close + 2] == 'X'))
    throw std::runtime_error("the editor exited during the measurement (run it alone to see why)");
  std::istringstream in(text.substr(close + 2));
  std::string field;
  long long utime = 0, stime = 0;
  // Fields after the command: state(3) ... utime(14) stime(15).
  for (int i = 3; i <= 15 && in >> field; ++i) {
    if (i == 14) utime = std::stoll(field);
    if (i == 15) stime = std::stoll(field);
  }
  return utime + stime;
}

struct Result {
  double median = 0, mean = 0;
};

Result measure(const std::vector<std::string>& command, double warmup, int seconds) {
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    std::vector<char*> argv;
    for (const std::string& a : command) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    std::perror("execv");
    std::_Exit(127);
  }
  const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
  std::this_thread::sleep_for(std::chrono::duration<double>(warmup));
  std::vector<double> samples;
  long long last = cpu_ticks(pid);
  const long long first = last;
  auto t0 = std::chrono::steady_clock::now(), prev = t0;
  for (int s = 0; s < seconds; ++s) {
    std::this_thread::sleep_until(t0 + std::chrono::seconds(s + 1));
    const auto now = std::chrono::steady_clock::now();
    const long long t = cpu_ticks(pid);
    const double dt = std::chrono::duration<double>(now - prev).count();
    samples.push_back(100.0 * static_cast<double>(t - last) / tick / dt);
    last = t;
    prev = now;
  }
  const double total = std::chrono::duration<double>(prev - t0).count();
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  Result r;
  r.mean = 100.0 * static_cast<double>(last - first) / tick / total;
  std::sort(samples.begin(), samples.end());
  r.median = samples[samples.size() / 2];
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    double warmup = 15;
    int seconds = 20, baseline_seconds = 5;
    std::vector<std::string> command;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--") {
        for (int j = i + 1; j < argc; ++j) command.emplace_back(argv[j]);
        break;
      }
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      if (a == "--warmup")
        warmup = std::stod(argv[++i]);
      else if (a == "--seconds")
        seconds = std::stoi(argv[++i]);
      else if (a == "--baseline-seconds")
        baseline_seconds = std::stoi(argv[++i]);
      else
        throw std::invalid_argument("unknown option " + a);
    }
    if (command.empty() || seconds < 1 || baseline_seconds < 1)
      throw std::invalid_argument(
          "usage: bench_editor_idle [--warmup S] [--seconds S] [--baseline-seconds S] -- "
          "caliper-editor ARGS...");
    std::vector<std::string> baseline = command;
    baseline.emplace_back("--no-idle-wait");
    const Result b = measure(baseline, warmup, baseline_seconds);
    std::printf(
        "baseline (--no-idle-wait, redraws every frame): CPU median %.1f %%, mean %.1f %% "
        "of one core over %d s\n",
        b.median, b.mean, baseline_seconds);
    const Result r = measure(command, warmup, seconds);
    std::printf("idle (waits for events): CPU median %.2f %%, mean %.2f %% of one core over %d s\n",
                r.median, r.mean, seconds);
    std::printf("ratio idle / baseline (means): %.4f\n", b.mean > 0 ? r.mean / b.mean : 0.0);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_editor_idle: %s\n", e.what());
    return 2;
  }
}
