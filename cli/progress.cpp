#include "progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>

namespace snag::cli {

namespace {

/// Columns of the terminal on standard error, asked at every redraw (the window may be
/// resized); 80 when it does not say.
size_t terminal_columns() {
  winsize size{};
  if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 80;
}

}  // namespace

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
  std::string line = "[";
  line.append(filled, '#');
  line.append(width - filled, '.');
  line += "] " + std::to_string(done) + "/" + std::to_string(total_) + "  " + note;
  // \r and "erase to end of line" redraw the bar in place, which only works while it fits one
  // line: a line that wrapped would leave its first rows behind at every redraw. So it is cut
  // a column short of the terminal's width (the last column would wrap on some terminals).
  // The notes are ASCII: a byte is a column.
  const size_t columns = terminal_columns();
  if (line.size() >= columns) line.resize(columns > 1 ? columns - 1 : 0);
  std::cerr << "\r\033[K" << line << std::flush;  // stderr is unbuffered
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
