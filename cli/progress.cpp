#include "progress.h"

#include <unistd.h>

#include <cstdio>
#include <iostream>

namespace snag::cli {

Progress::Progress(int64_t total, bool quiet)
    : total_(total), quiet_(quiet), bar_(!quiet && ::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() {
  finish();
}

void Progress::update(int64_t done, const std::string& note) {
  if (quiet_) return;
  if (!bar_) {
    std::cerr << "snag: [" << done << "/" << total_ << "] " << note << "\n";
    return;
  }
  constexpr int width = 30;
  const int filled = total_ > 0 ? static_cast<int>(width * done / total_) : width;
  std::string bar(filled, '#');
  bar.append(width - filled, '.');
  // \r and "erase to end of line" redraw the bar in place; stderr is unbuffered.
  std::cerr << "\r\033[K[" << bar << "] " << done << "/" << total_ << "  " << note << std::flush;
  drawn_ = true;
}

void Progress::finish() {
  if (drawn_) std::cerr << "\r\033[K" << std::flush;
  drawn_ = false;
}

void Progress::message(const std::string& line) {
  finish();
  std::cerr << line << "\n";
}

}  // namespace snag::cli
