// The CSV reports, byte for byte (RFC 4180: comma separated, "\n" line ends, a field with a
// comma, quote or line break quoted with its quotes doubled).
//
// pairs.csv:  frame,face_a,face_b,kind,poly_a,poly_b
//   one row per intersecting pair, face_a < face_b, rows sorted by (frame, face_a, face_b).
// frames.csv: frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,seconds,
//             rebuilt,topology_changed
//   one row per checked frame in frame order; `uncertain` counts the tests left to exact
//   arithmetic, `seconds` is the checking time (reading excluded) with 6 decimals, `rebuilt`
//   and `topology_changed` are 0 or 1.
#pragma once

#include <ostream>
#include <string>
#include <string_view>

#include "snag/report/report.h"

namespace snag::report {

inline constexpr std::string_view pairs_csv_header = "frame,face_a,face_b,kind,poly_a,poly_b";
inline constexpr std::string_view frames_csv_header =
    "frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,seconds,rebuilt,"
    "topology_changed";

/// The whole files for a report in memory: the header, then every frame's rows in increasing
/// frame number (stable, so frames recorded out of order still give sorted files).
void write_pairs_csv(std::ostream& out, const Report& report);
void write_frames_csv(std::ostream& out, const Report& report);

/// One frame's rows of pairs.csv, its pairs sorted by (a, b) whatever their order in the
/// record; nothing for a clean frame. The only formatter of these rows (ReportStream and
/// write_pairs_csv both use it).
void write_pairs_rows(std::ostream& out, const FrameRecord& frame);
/// One frame's row of frames.csv; the only formatter of that row.
void write_frames_row(std::ostream& out, const FrameRecord& frame);

/// `field` as one CSV field: unchanged unless it holds a comma, quote, CR or LF.
std::string csv_field(std::string_view field);

}  // namespace snag::report
