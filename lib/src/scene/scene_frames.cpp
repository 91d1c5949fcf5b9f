#include "snag/scene/scene_frames.h"

#include <algorithm>
#include <map>

#include "snag/error.h"

namespace snag::scene {

namespace {

constexpr std::string_view kDefaultGroup = "default";

/// A name for a message, shortened past 40 characters (an OBJ group name can be a whole line).
std::string shortened(const std::string& name) {
  if (name.size() <= 40) return name;
  size_t cut = 40;  // not inside a UTF-8 character: back to its first byte
  while (cut > 0 && (static_cast<unsigned char>(name[cut]) & 0xC0) == 0x80) --cut;
  return name.substr(0, cut) + "...";
}

/// Groups for a message: the first few, shortened, and how many more.
std::string listed_groups(const std::vector<std::string>& groups) {
  constexpr size_t kListed = 10;
  std::string text;
  for (size_t i = 0; i < groups.size() && i < kListed; ++i)
    text += (i ? ", " : "") + shortened(groups[i]);
  if (groups.size() > kListed) text += " and " + std::to_string(groups.size() - kListed) + " more";
  return text;
}

std::string group_of(const mesh::Mesh& mesh, size_t triangle) {
  const int32_t g = mesh.triangle_group.empty() ? -1 : mesh.triangle_group[triangle];
  return g < 0 ? std::string(kDefaultGroup) : mesh.group_names[g];
}

/// Appends object `object`'s part of `file_mesh` (the whole mesh, or the faces of one group
/// and the vertices they use, in file order) to the scene frame.
void append_object(SceneFrame& frame, const mesh::Mesh& file_mesh, const ObjectSpec& spec,
                   const std::string& file) {
  mesh::Mesh& out = frame.mesh;
  const auto vertex_base = static_cast<int32_t>(out.positions.size());
  // Groups of this object, merged into the scene's list by name.
  auto scene_group = [&](int32_t g) -> int32_t {
    if (g < 0) return -1;
    const std::string& name = file_mesh.group_names[g];
    const auto at = std::find(out.group_names.begin(), out.group_names.end(), name);
    if (at != out.group_names.end()) return static_cast<int32_t>(at - out.group_names.begin());
    out.group_names.push_back(name);
    return static_cast<int32_t>(out.group_names.size() - 1);
  };
  const size_t triangles = file_mesh.triangles.size();
  if (!spec.group) {
    out.positions.insert(out.positions.end(), file_mesh.positions.begin(),
                         file_mesh.positions.end());
    for (size_t v = 0; v < file_mesh.positions.size(); ++v)
      frame.file_vertex.push_back(static_cast<int32_t>(v));
    std::vector<int32_t> group_map(file_mesh.group_names.size());
    for (size_t g = 0; g < group_map.size(); ++g)
      group_map[g] = scene_group(static_cast<int32_t>(g));
    for (size_t t = 0; t < triangles; ++t) {
      geom::Tri tri = file_mesh.triangles[t];
      for (int k = 0; k < 3; ++k) tri.v[k] += vertex_base;
      out.triangles.push_back(tri);
      out.source_polygon.push_back(file_mesh.source_polygon[t]);
      const int32_t g = file_mesh.triangle_group.empty() ? -1 : file_mesh.triangle_group[t];
      out.triangle_group.push_back(g < 0 ? -1 : group_map[g]);
      frame.file_triangle.push_back(static_cast<int32_t>(t));
    }
  } else {
    // The group's faces, and the vertices they use renumbered in file order. Which of the
    // file's groups are the object's is decided once per group, not once per face (a name
    // compared per face was a string built per face, every frame): faces of no group are in
    // "default", and so are those of a group of that name.
    std::vector<uint8_t> wanted(file_mesh.group_names.size());
    for (size_t g = 0; g < wanted.size(); ++g) wanted[g] = file_mesh.group_names[g] == *spec.group;
    const bool wanted_ungrouped = *spec.group == kDefaultGroup;
    std::vector<int32_t> local(file_mesh.positions.size(), -1);
    std::vector<size_t> faces;
    for (size_t t = 0; t < triangles; ++t) {
      const int32_t g = file_mesh.triangle_group.empty() ? -1 : file_mesh.triangle_group[t];
      if (g < 0 ? wanted_ungrouped : wanted[g] != 0) {
        faces.push_back(t);
        for (int k = 0; k < 3; ++k) local[file_mesh.triangles[t].v[k]] = 0;
      }
    }
    if (faces.empty()) {
      throw InputError(file, 0,
                       "has no faces in group \"" + shortened(*spec.group) + "\" (object \"" +
                           shortened(spec.name) +
                           "\"); its groups: " + listed_groups(face_groups(file_mesh)));
    }
    int32_t next = vertex_base;
    for (size_t v = 0; v < local.size(); ++v)
      if (local[v] == 0) {
        local[v] = next++;
        out.positions.push_back(file_mesh.positions[v]);
        frame.file_vertex.push_back(static_cast<int32_t>(v));
      }
    const int32_t group = scene_group(
        file_mesh.triangle_group.empty() ? -1 : file_mesh.triangle_group[faces.front()]);
    for (size_t t : faces) {
      geom::Tri tri = file_mesh.triangles[t];
      for (int k = 0; k < 3; ++k) tri.v[k] = local[tri.v[k]];
      out.triangles.push_back(tri);
      out.source_polygon.push_back(file_mesh.source_polygon[t]);
      out.triangle_group.push_back(group);
      frame.file_triangle.push_back(static_cast<int32_t>(t));
    }
  }
  frame.layout.triangle_begin.push_back(static_cast<int32_t>(out.triangles.size()));
  frame.layout.vertex_begin.push_back(static_cast<int32_t>(out.positions.size()));
  frame.files.push_back(file);
  frame.polygons.push_back(file_mesh.polygon_count);
  frame.any_assimp = frame.any_assimp || file_mesh.ids_from_assimp;
}

}  // namespace

ResolvedScene resolve_scene(const Scene& scene, std::string_view frame_selection) {
  ResolvedScene resolved;
  const auto driver = std::find_if(scene.objects.begin(), scene.objects.end(),
                                   [](const ObjectSpec& o) { return o.role == Role::cloth; });
  if (driver == scene.objects.end()) throw UsageError("a scene needs at least one cloth");
  for (const ObjectSpec& spec : scene.objects) {
    ResolvedObject object;
    object.spec = spec;
    object.frames = seq::resolve_sequence(spec.sequence);
    resolved.objects.push_back(std::move(object));
  }
  const auto driver_index = static_cast<size_t>(driver - scene.objects.begin());
  resolved.frames = resolved.objects[driver_index].frames;
  if (!frame_selection.empty()) {
    const seq::FrameSelection selection = seq::FrameSelection::parse(frame_selection);
    resolved.absent_frames = selection.absent_runs(resolved.frames, ResolvedScene::kMostAbsentRuns,
                                                   &resolved.more_absent_frames);
    resolved.frames = seq::select_frames(resolved.frames, selection);
  } else {
    resolved.gaps = seq::frame_gaps(resolved.frames, ResolvedScene::kMostAbsentRuns);
  }
  for (size_t i = 0; i < resolved.objects.size(); ++i) {
    ResolvedObject& object = resolved.objects[i];
    if (i == driver_index) {
      object.frames = resolved.frames;
      continue;
    }
    if (object.frames.size() == 1) {
      object.still = true;
      continue;
    }
    // Each checked frame's file, by frame number.
    std::vector<seq::Frame> matched;
    for (const seq::Frame& f : resolved.frames) {
      const auto at =
          std::lower_bound(object.frames.begin(), object.frames.end(), f.number,
                           [](const seq::Frame& x, int64_t number) { return x.number < number; });
      if (at == object.frames.end() || at->number != f.number)
        throw InputError(object.spec.sequence, 0,
                         "has no file for frame " + std::to_string(f.number) + " (object \"" +
                             object.spec.name + "\"; " + f.path.string() +
                             " is that frame); an object's sequence must have every frame "
                             "checked, or be one file");
      matched.push_back(*at);
    }
    object.frames = std::move(matched);
  }
  for (int i : scene.self_checks()) resolved.checks.push_back({i, i});
  for (const auto& [a, b] : scene.cross_checks()) resolved.checks.push_back({a, b});
  std::sort(resolved.checks.begin(), resolved.checks.end());
  return resolved;
}

SceneReader::SceneReader(const ResolvedScene& scene)
    : scene_(&scene), still_(scene.objects.size()) {
  // Still objects of one file share its mesh.
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    if (!scene.objects[i].still) continue;
    for (size_t j = 0; j < i; ++j)
      if (scene.objects[j].still &&
          scene.objects[j].frames.front().path == scene.objects[i].frames.front().path) {
        still_[i] = still_[j];
        break;
      }
    if (still_[i].triangles.empty() && still_[i].positions.empty())
      still_[i] = io::read_mesh(scene.objects[i].frames.front().path);
  }
}

std::vector<io::FrameReader> SceneReader::make_readers() const {
  return std::vector<io::FrameReader>(scene_->objects.size());
}

SceneFrame SceneReader::read(size_t index, std::vector<io::FrameReader>& readers) const {
  SceneFrame frame;
  if (scene_->objects.size() == 1 && !scene_->objects[0].still && !scene_->objects[0].spec.group) {
    // A single mesh: the file's mesh as it is, its ids the scene's.
    const std::filesystem::path& path = scene_->objects[0].frames[index].path;
    frame.mesh = readers[0].read(path);
    frame.layout.triangle_begin = {0, static_cast<int32_t>(frame.mesh.triangles.size())};
    frame.layout.vertex_begin = {0, static_cast<int32_t>(frame.mesh.positions.size())};
    frame.files = {path.string()};
    frame.polygons = {frame.mesh.polygon_count};
    frame.any_assimp = frame.mesh.ids_from_assimp;
    return frame;
  }
  frame.layout.triangle_begin = {0};
  frame.layout.vertex_begin = {0};
  // Files read this frame: objects of one file (one group each) share its mesh.
  std::map<std::filesystem::path, mesh::Mesh> read;
  for (size_t i = 0; i < scene_->objects.size(); ++i) {
    const ResolvedObject& object = scene_->objects[i];
    if (object.still) {
      append_object(frame, still_[i], object.spec, object.frames.front().path.string());
      continue;
    }
    const std::filesystem::path& path = object.frames[index].path;
    auto at = read.find(path);
    if (at == read.end()) at = read.emplace(path, readers[i].read(path)).first;
    append_object(frame, at->second, object.spec, path.string());
  }
  return frame;
}

std::vector<std::string> face_groups(const mesh::Mesh& mesh) {
  std::vector<std::string> groups;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    std::string name = group_of(mesh, t);
    if (std::find(groups.begin(), groups.end(), name) == groups.end())
      groups.push_back(std::move(name));
  }
  return groups;
}

Scene scene_from_groups(const std::string& sequence, const std::vector<std::string>& groups,
                        const std::vector<std::string>& obstacle_groups,
                        std::optional<double> weld) {
  for (const std::string& name : obstacle_groups)
    if (std::find(groups.begin(), groups.end(), name) == groups.end())
      throw UsageError("--obstacle-group " + shortened(name) + ": " + sequence +
                       " has no such group; its groups: " + listed_groups(groups));
  Scene scene;
  for (const std::string& name : groups) {
    ObjectSpec object;
    object.name = name;
    object.sequence = sequence;
    object.group = name;
    object.weld = weld;
    const bool obstacle =
        std::find(obstacle_groups.begin(), obstacle_groups.end(), name) != obstacle_groups.end();
    object.role = obstacle ? Role::obstacle : Role::cloth;
    object.self = !obstacle;
    scene.objects.push_back(std::move(object));
  }
  if (!scene.objects.empty() && std::ranges::none_of(scene.objects, [](const ObjectSpec& o) {
        return o.role == Role::cloth;
      }))
    throw UsageError("--obstacle-group names every group of " + sequence + " (" +
                     listed_groups(groups) + "); at least one must be a cloth to check");
  for (ObjectSpec& object : scene.objects)
    if (object.role == Role::cloth)
      for (const ObjectSpec& other : scene.objects)
        if (other.name != object.name) object.against.push_back(other.name);
  return scene;
}

}  // namespace snag::scene
