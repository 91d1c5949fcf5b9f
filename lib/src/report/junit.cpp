#include "snag/report/junit.h"

#include <cstdio>

#include "snag/report/csv.h"

namespace snag::report {

namespace {

/// The length of the UTF-8 sequence at `text[at]` that XML 1.0 can hold, or 0 when it is not
/// one (a control character, a stray continuation byte, an overlong or truncated sequence, a
/// surrogate, U+FFFE or U+FFFF).
size_t valid_xml_sequence(std::string_view text, size_t at) {
  const auto byte = [&](size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(at);
  if (lead < 0x80) return lead >= 0x20 || lead == '\t' || lead == '\n' || lead == '\r' ? 1 : 0;
  const size_t length = lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC2 ? 2 : 0;
  if (length == 0 || lead > 0xF4 || at + length > text.size()) return 0;
  uint32_t code = lead & (0x7F >> length);
  for (size_t i = 1; i < length; ++i) {
    if ((byte(at + i) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(at + i) & 0x3F);
  }
  const uint32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < least[length] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF) ||
      code == 0xFFFE || code == 0xFFFF)
    return 0;
  return length;
}

std::string seconds_text(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6f", seconds);
  return text;
}

}  // namespace

std::string xml_escaped(std::string_view text, bool attribute) {
  std::string out;
  out.reserve(text.size());
  for (size_t at = 0; at < text.size();) {
    const size_t length = valid_xml_sequence(text, at);
    if (length == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++at;
      continue;
    }
    switch (text[at]) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      // A parser normalizes a line end to "\n" in text and every blank to a space in an
      // attribute: as references they come back as written.
      case '\r':
        out += "&#13;";
        break;
      case '\n':
        out += attribute ? "&#10;" : "\n";
        break;
      case '\t':
        out += attribute ? "&#9;" : "\t";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out.append(text, at, length);
    }
    at += length;
  }
  return out;
}

JunitReport::JunitReport(std::string suite, FailOn fail_on, std::vector<ObjectInput> objects)
    : suite_(std::move(suite)), fail_on_(fail_on), objects_(std::move(objects)) {}

void JunitReport::add(const FrameRecord& frame) {
  Case c;
  c.frame = frame.frame;
  c.file = frame.file;
  c.seconds = frame.times.total();
  // The failing pairs, the first kListedPairs of them as a frame of their own for the CSV
  // formatter (pairs.csv's rows, without its accepted column).
  FrameRecord failing;
  failing.frame = frame.frame;
  int64_t count = 0;
  for (const Pair& p : frame.pairs) {
    if (!pair_fails(p, fail_on_)) continue;
    if (failing.pairs.size() < kListedPairs) failing.pairs.push_back(p);
    ++count;
  }
  if (count > 0) {
    c.failed = true;
    const char* what = fail_on_ == FailOn::crossing ? " crossing pair" : " intersecting pair";
    c.message = std::to_string(count) + what + (count == 1 ? "" : "s") +
                (frame.accepted_count() > 0 ? " the baseline does not accept" : "") +
                " (--fail-on " + std::string(to_string(fail_on_)) + ")";
    c.text = pairs_csv_header_for(objects_) + "\n";
    append_pairs_rows(c.text, failing, objects_);
    if (count > static_cast<int64_t>(kListedPairs))
      c.text += "... and " + std::to_string(count - static_cast<int64_t>(kListedPairs)) + " more\n";
  }
  cases_.push_back(std::move(c));
}

void JunitReport::write(std::ostream& out) const {
  int64_t failures = 0;
  double seconds = 0;
  for (const Case& c : cases_) {
    failures += c.failed;
    seconds += c.seconds;
  }
  const std::string tests = std::to_string(cases_.size());
  const std::string counts =
      " tests=\"" + tests + "\" failures=\"" + std::to_string(failures) + "\"";
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out << "<testsuites name=\"snag check\"" << counts << " time=\"" << seconds_text(seconds)
      << "\">\n";
  out << "  <testsuite name=\"" << xml_escaped(suite_, true) << "\"" << counts
      << " skipped=\"0\" errors=\"0\" time=\"" << seconds_text(seconds) << "\">\n";
  for (const Case& c : cases_) {
    out << "    <testcase classname=\"snag.check\" name=\"frame " << c.frame << ": "
        << xml_escaped(c.file, true) << "\" time=\"" << seconds_text(c.seconds) << "\"";
    if (!c.failed) {
      out << "/>\n";
      continue;
    }
    out << ">\n      <failure type=\"" << (fail_on_ == FailOn::crossing ? "crossing" : "any")
        << "\" message=\"" << xml_escaped(c.message, true) << "\">" << xml_escaped(c.text, false)
        << "</failure>\n    </testcase>\n";
  }
  out << "  </testsuite>\n</testsuites>\n";
}

}  // namespace snag::report
