// report.json composed of pieces, so that ReportStream can write its two arrays that grow with
// the run (inputs.files and frames) as frames finish and everything else at the end, while the
// bytes stay those nlohmann's dump(2) gives for the whole document (two-space indentation,
// "key": value, one element or member per line, [] for an empty array). Private to snag::lib;
// json.h's report_json is the same composition in memory.
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
/// one per object, throws InternalError.
std::string json_frame_element(const FrameRecord& frame, bool first,
                               std::span<const ObjectInput> objects);

/// Writes report.json: `run`'s head (version, settings, inputs) and totals (builds, rebuilds,
/// wall seconds), the elements `write_files` and `write_frames` write (what the *_element
/// functions gave, in order), and `summary`, whose frames_checked says whether the two arrays
/// have elements. run.frames is not read; run.inputs.objects, when not empty, adds
/// inputs.objects and the summary's scene members.
void write_report_json(std::ostream& out, const Report& run, const Summary& summary,
                       const std::function<void(std::ostream&)>& write_files,
                       const std::function<void(std::ostream&)>& write_frames);

}  // namespace snag::report
