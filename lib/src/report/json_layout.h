// report.json composed of pieces, so that ReportStream can write its two arrays that grow with
// the run (frames, into the file itself, and inputs.files) as frames finish and everything
// else at the end, while the bytes stay those nlohmann's dump(2) gives for the whole document
// (two-space indentation, "key": value, one element or member per line, [] for an empty array),
// except that each of a frame's pairs is one line, as dump() writes the pair's object.
// Private to snag::lib; json.h's report_json is the same composition in memory.
#pragma once

#include <functional>
#include <ostream>
#include <span>
#include <string>

#include "snag/report/report.h"

namespace snag::report {

/// One element of inputs.files, as it follows the array's "[" (`first`) or the previous
/// element.
std::string json_file_element(const std::string& file, bool first);
/// One element of frames (the frame's record), as it follows "[" (`first`) or the previous one.
/// `objects`: the run's Inputs::objects, empty for a single mesh; in a scene run the record
/// also names the objects of its pairs and degenerate faces and has the scene members
/// (objects, checks, penetration). An object index outside `objects`, or frame.objects not
/// one per object, throws InternalError. `baseline` (Settings::baseline set): each pair's
/// `accepted` and the counts' `accepted`.
std::string json_frame_element(const FrameRecord& frame, bool first,
                               std::span<const ObjectInput> objects, bool baseline);
/// json_frame_element's text appended to `out`, a buffer the caller can keep from frame to frame
/// (ReportStream's writer does).
void append_json_frame_element(std::string& out, const FrameRecord& frame, bool first,
                               std::span<const ObjectInput> objects, bool baseline);

/// Writes report.json: `run`'s head (version, settings), the frames elements `write_frames`
/// writes (what json_frame_element gave, in order), then the inputs with the inputs.files
/// elements `write_files` writes (json_file_element), and `summary`, whose frames_checked says
/// whether the two arrays have elements, with `run`'s totals (builds, rebuilds, wall seconds).
/// The inputs follow the frames because a run knows them only at its end (the files read,
/// whose ids, the vertices welded), while the frames, most of the bytes, can then go straight
/// to the file as they finish. run.frames is not read; run.inputs.objects, when not empty,
/// adds inputs.objects and the summary's scene members; run.settings.baseline, when set,
/// settings.baseline, inputs.baseline (run.inputs.baseline) and the summary's baseline members.
void write_report_json(std::ostream& out, const Report& run, const Summary& summary,
                       const std::function<void(std::ostream&)>& write_files,
                       const std::function<void(std::ostream&)>& write_frames);

/// write_report_json in two parts around the frames elements, for a file written as the run
/// goes: the head, up to and including the frames array's "[" (needs only run's version and
/// settings), and the tail, from the array's "]" to the end.
void write_report_json_head(std::ostream& out, const Report& run);
void write_report_json_tail(std::ostream& out, const Report& run, const Summary& summary,
                            const std::function<void(std::ostream&)>& write_files);

}  // namespace snag::report
