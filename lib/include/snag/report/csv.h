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

void write_pairs_csv(std::ostream& out, const Report& report);
void write_frames_csv(std::ostream& out, const Report& report);

/// `field` as one CSV field: unchanged unless it holds a comma, quote, CR or LF.
std::string csv_field(std::string_view field);

}  // namespace snag::report
