// Scenes: the objects `snag check` checks together each frame (a cloth against itself and against
// a body, never the body against itself unless asked), from a scene file or from the flags of
// `snag check CLOTH --obstacle A --obstacle B`.
//
// A scene file is JSON:
//
//   { "schema": "snag-scene/1",
//     "objects": [
//       {"name": "dress", "sequence": "dress.%04d.obj", "role": "cloth", "weld": 1e-6,
//        "ignore": [["collar", "*"]]},
//       {"name": "body", "sequence": "body.%04d.obj", "role": "obstacle"},
//       {"name": "floor", "sequence": "floor.obj", "role": "obstacle", "against": ["dress"]}
//     ] }
//
// Top level: "objects" (required, a non-empty array) and "schema" (optional; when present it must
// be "snag-scene/1"). Each object: "name" and "sequence" (required, non-empty strings), "role"
// ("cloth", the default, or "obstacle"), "group" (a non-empty string), "self" (true or false),
// "against" (an array of names), "weld" (a number >= 0), "ignore" (an array of [a, b] pairs of
// group names). Any other key, a duplicate key, or a value of the wrong type is an error. Here
// dress is checked against itself, against body (by default) and against floor (listed by both);
// body and floor are not checked against themselves or each other.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace snag::scene {

enum class Role { cloth, obstacle };

/// Pairs whose faces lie in these two OBJ groups (`o`/`g` names) are left out of the report
/// (e.g. a pinned seam): one face in group `a` of the object the rule belongs to, the other in
/// group `b` of the object it is checked against (or of the same object). "*" matches any group.
struct IgnoreRule {
  std::string a;
  std::string b;
  bool operator==(const IgnoreRule&) const = default;
};

/// One object of a scene. After read_scene_file, parse_scene or scene_from_flags, `self` and
/// `against` hold the resolved values, defaults filled in.
struct ObjectSpec {
  std::string name;  ///< unique in the scene, non-empty
  /// A SEQUENCE as snag check takes it (file, directory, pattern, glob; seq::resolve_sequence).
  /// From a scene file a relative sequence is resolved against the scene file's directory.
  std::string sequence;
  Role role = Role::cloth;
  std::optional<std::string> group;  ///< only the faces of this OBJ group of the files
  /// Whether its self-intersections are checked; in a file the default is true for a cloth and
  /// false for an obstacle.
  bool self = true;
  /// Names of the objects it is checked against, never its own. In a file the default is every
  /// obstacle for a cloth and none for an obstacle (checks are symmetric: a cloth that lists an
  /// obstacle, or is checked against it by default, is enough); an explicit [] means none.
  std::vector<std::string> against;
  std::optional<double> weld;  ///< weld tolerance for adjacency (>= 0); none: no welding asked
  std::vector<IgnoreRule> ignore;
  bool operator==(const ObjectSpec&) const = default;
};

struct Scene {
  std::vector<ObjectSpec> objects;

  /// The unordered pairs of objects checked against each other, as indices into `objects`:
  /// (i, j) with i < j for every j named in objects[i].against or i named in objects[j].against,
  /// sorted and unique. Throws snag::InternalError when an `against` name is not exactly one
  /// other object's (never so for a scene from the functions below).
  std::vector<std::pair<int, int>> cross_checks() const;
  /// The indices of the objects checked against themselves (`self`), ascending.
  std::vector<int> self_checks() const;
};

/// Reads and validates a scene file (JSON, see above). Every mistake is a snag::InputError naming
/// the file, the line where the offending value (or key) starts, and its key path, e.g.
/// `scene.json:4: objects[1].role: expected "cloth" or "obstacle", got "body"`. Also an error:
/// a file that cannot be read, invalid JSON (with the line and column where parsing stopped), an
/// object listed in its own "against", an "against" name no object has, a scene without a cloth.
Scene read_scene_file(const std::string& path);

/// The same validation of text already read; `path` names the file in messages and is the base
/// of relative sequences (its directory; none when `path` has no directory part).
Scene parse_scene(std::string_view text, const std::string& path);

/// The scene of the command-line shorthand `snag check CLOTH --obstacle A --obstacle B`: object
/// "cloth" (role cloth, self, against every obstacle) and one obstacle per sequence in the given
/// order (no self check, against nothing: the cloth's list is enough); `weld` on every object.
/// An obstacle is named after its file name less extension, frame token, glob characters, and
/// trailing separators and frame digits (digits after a separator, or 3 or more: "body" for
/// body.%04d.obj, body.0001.obj, body0001.obj or body_*.ply, "body_v2" for body_v2.obj); when
/// nothing is left, after its directory (body/%04d.obj, body/), else "obstacle". A name that is
/// taken or is "cloth" gets the first free suffix "-2", "-3", ... Sequences are kept as given.
Scene scene_from_flags(const std::string& cloth_sequence,
                       const std::vector<std::string>& obstacle_sequences,
                       std::optional<double> weld);

}  // namespace snag::scene
