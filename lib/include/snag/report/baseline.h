// A baseline of accepted pairs (`snag check --baseline FILE`): pairs an earlier run found and
// someone accepted (a button sewn through its placket, a pinned seam), so that a CI gate fails
// on new intersections only. The file is a pairs.csv, as snag writes it or cut down by hand:
//
//   frame,face_a,face_b,kind,poly_a,poly_b[,object_a,object_b][,accepted]
//
// Columns are found by their header names, in any order (spaces and tabs around a name or a
// value, quoted or not, are dropped); frame, face_a and face_b are required, object_a and object_b
// exactly when the run has objects (--obstacle, --scene, --split-groups), kind and accepted are
// optional, every other column (poly_a, poly_b) is ignored, and a row may stop before optional
// columns. Each row is an accepted pair:
// - frame: the frame number, or `*` for every frame;
// - face_a, face_b: triangle ids as pairs.csv gives them (not polygon ids), in either order;
// - kind: `crossing` accepts the pair whatever its kind, `touching` only while it touches (a
//   touching pair that starts to cross is new), `*` or empty as crossing;
// - object_a, object_b: object names as the run's reports give them (CSV quoting understood);
// - accepted: 1 or empty, or 0 for a row left out: the pairs.csv of a run with a baseline marks
//   its new pairs 0, and a file taken from it as the next baseline must not accept them unseen.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "snag/report/report.h"

namespace snag::report {

class Baseline {
 public:
  /// Reads the baseline at `path` for a run with these objects (Inputs::objects; empty for a
  /// single mesh, whose pairs are all of object 0). Throws InputError naming the file, the line
  /// and what is wrong: a directory or unreadable file, no header, a required column missing
  /// (or object columns in a single-mesh run), a short row, a frame or face id that is not one,
  /// an unknown kind or accepted value, an object the run does not have, a face paired with
  /// itself, bad quoting.
  static Baseline read(const std::filesystem::path& path, std::span<const ObjectInput> objects);
  /// The same from text in memory; `name` stands for the file in messages.
  static Baseline parse(std::string_view text, const std::string& name,
                        std::span<const ObjectInput> objects);

  /// Sets Pair::accepted on each of `frame`'s pairs that the baseline accepts (and clears it
  /// on the others), and notes which entries accepted a pair and which frames were checked.
  /// Frames come in the order they were checked. Throws InputError (the file and the entry's
  /// line) when an entry for this frame names a face past the frame's triangles: single-mesh
  /// runs, and the objects of a scene that are whole files (an OBJ group's ids are its file's,
  /// not counted here); every-frame entries only up to the first frame whose face list changed.
  /// frame.triangles (single mesh) or frame.objects[i].triangles must be the frame's.
  void mark(FrameRecord& frame);

  /// Distinct pairs listed (a pair listed twice for one frame, or for every frame, is one
  /// entry; its kinds combined).
  int64_t entries() const { return static_cast<int64_t>(entries_.size()); }
  /// What the run made of the file so far: its entries, the rows it left out (accepted 0), the
  /// entries for the frames marked (every-frame entries once a frame is marked), and of those
  /// the ones that accepted no pair (a fixed intersection, or one that got worse: touching in
  /// the baseline, crossing now), with their lines.
  BaselineUse use() const;

 private:
  /// One accepted pair, ordered as the reports order a pair: (object_a, a) < (object_b, b).
  struct Entry {
    int64_t frame = 0;  ///< not read for every-frame entries
    int64_t line = 0;   ///< the file's line of its first row
    int32_t object_a = 0, a = 0, object_b = 0, b = 0;
    bool crossing_accepted = true;  ///< false: only while the pair touches
    bool checked = false;           ///< its frame was marked (every-frame entries: any frame)
    bool matched = false;           ///< it accepted a pair
  };
  std::string name_;  ///< the file, for messages
  /// Per object: whether its ids are those of a whole file counted by its triangles (a single
  /// mesh, or a scene object that is not an OBJ group), so that mark() can bound them.
  std::vector<bool> whole_file_;
  std::vector<std::string> object_names_;  ///< a scene's, for messages
  bool face_list_changed_ = false;         ///< a frame marked so far had a topology change
  /// The entries of numbered frames, sorted by (frame, object_a, a, object_b, b), then from
  /// every_frame_begin_ on those of every frame, sorted by (object_a, a, object_b, b).
  std::vector<Entry> entries_;
  size_t every_frame_begin_ = 0;
  int64_t left_out_ = 0;  ///< rows marked accepted 0
};

}  // namespace snag::report
