// The CSV reports, byte for byte (RFC 4180: comma separated, "\n" line ends, a field with a
// comma, quote or line break, or a space or tab at either end, quoted with its quotes doubled).
//
// pairs.csv:  frame,face_a,face_b,kind,poly_a,poly_b
//   one row per intersecting pair, face_a < face_b, rows sorted by (frame, face_a, face_b).
// frames.csv: frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,seconds,
//             rebuilt,topology_changed
//   one row per checked frame in frame order; `uncertain` counts the tests left to exact
//   arithmetic, `seconds` is the checking time (reading excluded) with 6 decimals, `rebuilt`
//   and `topology_changed` are 0 or 1.
//
// A scene run (Inputs::objects not empty: --obstacle, --scene, --split-groups) has more columns,
// only then; a single-mesh run's files keep the columns above, byte for byte:
// pairs.csv:  ...,poly_b,object_a,object_b
//   the objects' names (csv_field-quoted); face and poly ids are those of each object's own
//   file, so face_a < face_b holds only within one object; rows sorted by (frame, pair_order).
// frames.csv: ...,topology_changed,reused_pairs,inside_vertices,max_depth
//   FrameRecord::reused_pairs(), inside_vertices() and max_depth() (6 decimals).
//
// A run with a baseline (Settings::baseline) has one more column in each file, last:
// pairs.csv:  ...,accepted      1 when the baseline accepts the pair (Pair::accepted), else 0
// frames.csv: ...,accepted      FrameRecord::accepted_count()
#pragma once

#include <ostream>
#include <span>
#include <string>
#include <string_view>

#include "snag/report/report.h"

namespace snag::report {

inline constexpr std::string_view pairs_csv_header = "frame,face_a,face_b,kind,poly_a,poly_b";
inline constexpr std::string_view frames_csv_header =
    "frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,seconds,rebuilt,"
    "topology_changed";
inline constexpr std::string_view scene_pairs_csv_header =
    "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b";
inline constexpr std::string_view scene_frames_csv_header =
    "frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,seconds,rebuilt,"
    "topology_changed,reused_pairs,inside_vertices,max_depth";

/// The header for a run with these objects (Inputs::objects): the scene header when there
/// are any, else the single-mesh one; with `baseline`, the accepted column after them.
/// Without the line end.
std::string pairs_csv_header_for(std::span<const ObjectInput> objects, bool baseline = false);
std::string frames_csv_header_for(std::span<const ObjectInput> objects, bool baseline = false);

/// The whole files for a report in memory: the header, then every frame's rows in increasing
/// frame number (stable, so frames recorded out of order still give sorted files). The
/// columns are chosen by report.inputs.objects (empty: single mesh) and
/// report.settings.baseline.
void write_pairs_csv(std::ostream& out, const Report& report);
void write_frames_csv(std::ostream& out, const Report& report);

/// One frame's rows of pairs.csv, its pairs sorted by pair_order whatever their order in the
/// record; nothing for a clean frame. `objects`: the run's Inputs::objects, empty for a single
/// mesh (the object columns are left out and Pair::object_a/b are not read); in a scene run
/// every pair's object_a and object_b must index it (else InternalError). `baseline`: the
/// accepted column last. The only formatter of these rows (ReportStream and write_pairs_csv
/// both use it).
void write_pairs_rows(std::ostream& out, const FrameRecord& frame,
                      std::span<const ObjectInput> objects = {}, bool baseline = false);
/// write_pairs_rows's rows appended to `out`, a buffer the caller can keep from frame to frame
/// (ReportStream's writer does), then written at once: a stream write per row took about as
/// long as formatting the rows.
void append_pairs_rows(std::string& out, const FrameRecord& frame,
                       std::span<const ObjectInput> objects = {}, bool baseline = false);
/// One frame's row of frames.csv, with the scene columns when `objects` (the run's
/// Inputs::objects) is not empty and the accepted column with `baseline`; the only formatter
/// of that row.
void write_frames_row(std::ostream& out, const FrameRecord& frame,
                      std::span<const ObjectInput> objects = {}, bool baseline = false);

/// `field` as one CSV field: unchanged unless it holds a comma, quote, CR or LF, or begins or
/// ends with a space or tab.
std::string csv_field(std::string_view field);

}  // namespace snag::report
