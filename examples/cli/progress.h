// Progress of a long run, shown on a terminal.
#ifndef RCM_EXAMPLES_CLI_PROGRESS_H_
#define RCM_EXAMPLES_CLI_PROGRESS_H_

#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <iostream>
#include <string>

namespace rcm::cli {

// Shows "WHAT [#########.........] k of N, R/s, ETA Ts  STATUS" on one
// terminal line of stderr, rewritten in place, for runs long enough to
// wait for; silent when stderr is redirected (logs and tests stay clean).
// The line is erased at the end.
class Progress {
 public:
  Progress(const char* what, size_t total)
      : what_(what),
        total_(total),
        enabled_(isatty(STDERR_FILENO) != 0),
        start_(std::chrono::steady_clock::now()) {}
  ~Progress() {
    if (shown_) std::cerr << "\r\033[K" << std::flush;
  }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // `status`: a short note for the end of the line, e.g. the current n.
  void Update(size_t done, const std::string& status = "") {
    if (!enabled_ || total_ < 2) return;
    constexpr size_t kBarWidth = 24;
    const size_t filled = kBarWidth * done / total_;
    const double seconds = std::chrono::duration<double>(
                               std::chrono::steady_clock::now() - start_)
                               .count();
    std::string line = std::string("\r\033[K") + what_ + " [" +
                       std::string(filled, '#') +
                       std::string(kBarWidth - filled, '.') + "] " +
                       std::to_string(done) + " of " + std::to_string(total_);
    if (done > 0 && seconds > 0.0) {
      const double rate = done / seconds;
      char text[64];
      std::snprintf(text, sizeof(text), ", %.1f/s, ETA %.0f s", rate,
                    (total_ - done) / rate);
      line += text;
    }
    if (!status.empty()) line += "  " + status;
    std::cerr << line << std::flush;
    shown_ = true;
  }

 private:
  const char* what_;
  size_t total_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  bool shown_ = false;
};

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_PROGRESS_H_
