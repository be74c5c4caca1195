// Progress of a long run, shown on a terminal.
#ifndef RCM_EXAMPLES_CLI_PROGRESS_H_
#define RCM_EXAMPLES_CLI_PROGRESS_H_

#include <unistd.h>

#include <cstddef>
#include <iostream>

namespace rcm::cli {

// Shows "WHAT k of N (p %)" on one terminal line of stderr, rewritten in
// place, for runs long enough to wait for; silent when stderr is
// redirected (logs and tests stay clean). The line is erased at the end.
class Progress {
 public:
  Progress(const char* what, size_t total)
      : what_(what), total_(total), enabled_(isatty(STDERR_FILENO) != 0) {}
  ~Progress() {
    if (shown_) std::cerr << "\r\033[K" << std::flush;
  }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void Update(size_t done) {
    if (!enabled_ || total_ < 2) return;
    std::cerr << "\r" << what_ << " " << done << " of " << total_ << " ("
              << (100 * done / total_) << " %)" << std::flush;
    shown_ = true;
  }

 private:
  const char* what_;
  size_t total_;
  bool enabled_;
  bool shown_ = false;
};

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_PROGRESS_H_
