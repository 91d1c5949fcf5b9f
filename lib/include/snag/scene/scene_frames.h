// A scene's objects matched with their files, and each checked frame read as one mesh: the
// objects laid end to end (detect::PartLayout), so that one checker holds them all with a tree
// per object. An object is the whole of its files, or one OBJ group of them (objects inside one
// file); a still object (one file for every frame) is read once.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "snag/detect/topology.h"
#include "snag/io/read_mesh.h"
#include "snag/mesh/mesh.h"
#include "snag/scene/scene.h"
#include "snag/seq/sequence.h"

namespace snag::scene {

struct ResolvedObject {
  ObjectSpec spec;
  /// Its file for each checked frame (ResolvedScene::frames), or a single one when still.
  std::vector<seq::Frame> frames;
  bool still = false;
};

struct ResolvedScene {
  std::vector<ResolvedObject> objects;
  /// The checked frames: the first cloth's, less those --frames leaves out.
  std::vector<seq::Frame> frames;
  /// Numbers --frames names that the first cloth's sequence lacks, as runs
  /// (seq::FrameSelection::absent_runs, at most kMostAbsentRuns): a cache cut short or with a
  /// frame missing, which the user is told of.
  std::vector<std::string> absent_frames;
  bool more_absent_frames = false;  ///< more runs are absent than absent_frames holds
  static constexpr size_t kMostAbsentRuns = 6;
  /// Without --frames: the numbers the first cloth's sequence skips (seq::frame_gaps, at most
  /// kMostAbsentRuns runs), a frame a cache lost, which the user is told of.
  seq::FrameGaps gaps;
  /// The object pairs checked (a <= b; a == b: self), in increasing order.
  std::vector<detect::PartCheck> checks;
};

/// Resolves every object's sequence (seq::resolve_sequence). The first cloth sets the frames
/// (`frame_selection` as --frames takes it, empty for all); an object with a single file that
/// is not one of several frames is still; any other must have a file for every checked frame
/// number. Throws snag::InputError naming the object and the missing frame, or UsageError for
/// a bad selection.
ResolvedScene resolve_scene(const Scene& scene, std::string_view frame_selection);

/// One checked frame of every object, laid end to end in scene order.
struct SceneFrame {
  /// positions and triangles (vertex ids scene-wide), source_polygon (each object's file's
  /// face ids), triangle_group into group_names (the groups of every object, merged).
  mesh::Mesh mesh;
  detect::PartLayout layout;
  /// Per triangle: its id in its object's file (an object of one group keeps the file's ids).
  /// Empty for a scene of one whole mesh, whose ids are the file's.
  std::vector<int32_t> file_triangle;
  /// Per vertex: its id in its object's file (the same emptiness as file_triangle).
  std::vector<int32_t> file_vertex;
  std::vector<std::string> files;  ///< per object, this frame's file
  std::vector<int64_t> polygons;   ///< per object, faces in its file
  bool any_assimp = false;         ///< some object's ids are assimp's
};

/// Reads scene frames: one per call, from any thread, each with its own FileReaders.
class SceneReader {
 public:
  /// Reads the still objects now (their errors are thrown here).
  explicit SceneReader(const ResolvedScene& scene);

  /// One FrameReader per object that is not still (each keeps the structure of its own
  /// files); a calling thread owns one set.
  std::vector<io::FrameReader> make_readers() const;

  /// Checked frame `index`, every object's file read once (objects of one file share it).
  SceneFrame read(size_t index, std::vector<io::FrameReader>& readers) const;

 private:
  const ResolvedScene* scene_;
  std::vector<mesh::Mesh> still_;  ///< per object: the mesh of a still one (else empty)
};

/// The names of the OBJ groups with faces in `mesh`, in order of first use; faces before any
/// group are in "default".
std::vector<std::string> face_groups(const mesh::Mesh& mesh);

/// The scene of `--split-groups`: each group of SEQUENCE's first frame (face_groups) becomes an
/// object of that group; those named in `obstacle_groups` are obstacles, the others cloth,
/// each cloth checked against itself and every other object. Throws UsageError for an
/// obstacle group the file does not have.
Scene scene_from_groups(const std::string& sequence, const std::vector<std::string>& groups,
                        const std::vector<std::string>& obstacle_groups,
                        std::optional<double> weld);

}  // namespace snag::scene
