// report.json, schema "snag-report/2" (documented field by field in man/snag.1, REPORT.JSON):
//
//   { "schema": "snag-report/2", "snag": {"version"},
//     "settings": {backend, backend_requested, threads, exact, weld, rebuild, rebuild_threshold,
//                  fail_on, frames},
//     "inputs":   {sequence, ids, files: [...], coincident_vertices, welded_vertices},
//     "frames":   [ {frame, file, vertices, triangles, polygons, topology_changed, rebuilt,
//                    tree_quality, counts: {pairs, crossing, touching, degenerate,
//                    candidate_pairs, filtered_tests, uncertain_tests},
//                    seconds: {read, build, refit, traverse, exact, classify, total},
//                    pairs: [{a, b, kind, poly_a, poly_b}], degenerate: [{face, poly}]} ],
//     "summary":  {frames_checked, frames_with_crossings, frames_with_pairs,
//                  worst_frame: {frame, file, crossing, pairs} | null, pairs, crossing,
//                  touching, degenerate, uncertain_tests, topology_changes, builds, rebuilds,
//                  seconds: {check, read, wall}, failed} }
//
// A scene run (Inputs::objects not empty: --obstacle, --scene, --split-groups) adds keys, still
// under "snag-report/2" (they are additive, and a single-mesh run's report has none of them):
//
//     inputs.objects: [{name, role, sequence, group | null, still, weld | null, vertices,
//                       triangles, closed | null (cloth)}]  after welded_vertices;
//     in each frame record: pairs[] gain object_a, object_b (names) after poly_b;
//                           degenerate[] gain object (name); after degenerate come
//       objects: [{name, file, moved, rebuilt, build_seconds, refit_seconds, tree_quality}]
//                (one per object, in inputs.objects order),
//       checks: [{objects: [name_a, name_b], pairs, reused, seconds}],
//       penetration: [{cloth, obstacle (names), vertices, inside, ratio, max_depth,
//                      mean_depth, p95_depth}];
//     summary: reused_pairs, max_depth  after topology_changes.
//
// Within schema version 2, fields may be added but none is removed or changes meaning.
#pragma once

#include <string>
#include <string_view>

#include "snag/report/report.h"

namespace snag::report {

inline constexpr std::string_view json_schema = "snag-report/2";

/// The report as JSON text (two-space indentation, a trailing newline), frames in the order of
/// report.frames. ReportStream writes the same bytes piece by piece.
std::string report_json(const Report& report);

}  // namespace snag::report
