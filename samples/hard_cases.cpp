// snag-hard-cases: writes the hard-case corpus of samples/hard/: small OBJ meshes of exact and
// one-ulp-from-exact contacts, each with the intersecting pairs and kinds its construction
// implies. Every answer below is written beside its construction and argued there; none is
// taken from snag's output (tests/validators/hard_cases_test.cpp checks snag and CGAL
// against them).
//
//   snag-hard-cases -o DIR        write the corpus into DIR (created if missing)
//   snag-hard-cases --check DIR   exit 1, naming the files, when DIR differs from what -o writes
//
// Standard library only: it builds and runs without any of snag's targets.
//
// Kinds (docs: /work/shared/BRIEF.md, "What counts as an intersection"): `crossing` when the
// triangles are not coplanar, each has corners strictly on both sides of the other's plane, and
// they share a segment of positive length; `touching` for every other intersecting pair. Faces
// sharing an edge intersect only when coplanar and folded onto each other; faces sharing one
// vertex intersect when they meet anywhere but that vertex. Shared means the same vertex id
// (after --weld when a case says so), never merely the same position.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace {

using P3 = std::array<double, 3>;
enum class Kind { crossing, touching };
enum Axis { X = 0, Y = 1, Z = 2 };

struct Pair {
  int a, b;
  Kind kind;
};

/// One coordinate moved by one unit in the last place, after every transform:
/// std::nextafter(value, direction > 0 ? +inf : -inf).
struct Nudge {
  int vertex;
  int axis;
  int direction;
};

/// A small mesh with its expected answer (no weld). Vertex and face ids are 0-based, file order.
struct Config {
  std::vector<P3> v;
  std::vector<std::array<int, 3>> f;
  std::vector<Pair> pairs;
  std::vector<int> degenerate;
  std::vector<Nudge> nudges;

  int vertex(P3 p) {
    v.push_back(p);
    return static_cast<int>(v.size()) - 1;
  }
  int face(int a, int b, int c) {
    f.push_back({a, b, c});
    return static_cast<int>(f.size()) - 1;
  }
  int tri(P3 a, P3 b, P3 c) {
    const int i = vertex(a), j = vertex(b), k = vertex(c);
    return face(i, j, k);
  }
  Config& pair(int a, int b, Kind kind) {
    pairs.push_back({a, b, kind});
    return *this;
  }
  Config& nudge(int vertex_id, int axis, int direction) {
    nudges.push_back({vertex_id, axis, direction});
    return *this;
  }
  Config& expect(std::vector<Pair> p) {
    pairs = std::move(p);
    return *this;
  }
};

/// How a case is checked: the weld tolerance ("" for none) and the pairs expected with it.
struct Variant {
  std::string suffix;  // appended to the case name
  std::string weld;
  std::vector<Pair> pairs;
};

struct Case {
  std::string name;
  std::string description;
  Config mesh;
  std::vector<Variant> variants = {};  // empty: one variant, no weld, mesh.pairs
  bool decimal_micro = false;          // write each (integer) coordinate N as "Ne-6"
};

const double kH = std::ldexp(1.0, -40);  // a sliver's height

// The triangle most configurations meet: z = 0, corners (0,0,0) (4,0,0) (0,4,0); its interior
// is x > 0, y > 0, x + y < 4.
Config t0() {
  Config c;
  c.tri({0, 0, 0}, {4, 0, 0}, {0, 4, 0});
  return c;
}

// ---------------------------------------------------------------------------------------------
// Coplanar configurations.

Config coplanar_overlap() {  // (1,1) is inside face 0: the overlap has positive area
  Config c = t0();
  c.tri({1, 1, 0}, {5, 1, 0}, {1, 5, 0});
  return c.pair(0, 1, Kind::touching);
}
Config coplanar_inside() {  // face 1 strictly inside face 0: no edges cross at all
  Config c;
  c.tri({0, 0, 0}, {8, 0, 0}, {0, 8, 0});
  c.tri({1, 1, 0}, {3, 1, 0}, {1, 3, 0});
  return c.pair(0, 1, Kind::touching);
}
Config coplanar_apart() {  // boxes overlap; face 1 is in x + y >= 5
  Config c = t0();
  c.tri({4, 1, 0}, {4, 4, 0}, {1, 4, 0});
  return c;
}
Config
coplanar_edges_overlap() {  // edges collinear on y = 0 overlapping on [1,4]; face 1 in y <= 0
  Config c = t0();
  c.tri({1, 0, 0}, {3, -2, 0}, {5, 0, 0});
  return c.pair(0, 1, Kind::touching);
}
// Face 0 is (0,0) (4,4) (0,4): the region y >= x, x >= 0, y <= 4. Vertex 3 (2,2) is on its edge
// y = x; face 1 lies in y <= x. Moving x of vertex 3 down puts it inside face 0 (overlap), up
// takes face 1 strictly into y < x (apart).
Config coplanar_vertex_on_edge() {
  Config c;
  c.tri({0, 0, 0}, {4, 4, 0}, {0, 4, 0});
  c.tri({2, 2, 0}, {3, 0, 0}, {4, 1, 0});
  return c.pair(0, 1, Kind::touching);
}
// Shared edge (0,0,1)-(4,0,1) in the plane z = 1; the third corners (1,3,1) and (3,2,1) are on
// the same side of it, so the faces are folded flat onto each other.
Config coplanar_shared_edge_folded() {
  Config c;
  c.vertex({0, 0, 1});
  c.vertex({4, 0, 1});
  c.vertex({1, 3, 1});
  c.vertex({3, 2, 1});
  c.face(0, 1, 2);
  c.face(1, 0, 3);
  return c.pair(0, 1, Kind::touching);
}
Config coplanar_shared_edge_flat() {  // the same with (2,-3,1): an ordinary flat mesh
  Config c;
  c.vertex({0, 0, 1});
  c.vertex({4, 0, 1});
  c.vertex({1, 3, 1});
  c.vertex({2, -3, 1});
  c.face(0, 1, 2);
  c.face(1, 0, 3);
  return c;
}
// Shared vertex 0 at the origin. Face 0 spans the directions 0 to 26.6 degrees.
Config coplanar_shared_vertex(P3 b1, P3 b2) {
  Config c;
  c.vertex({0, 0, 0});
  c.vertex({4, 0, 0});
  c.vertex({4, 2, 0});
  c.face(0, 1, 2);
  const int i = c.vertex(b1), j = c.vertex(b2);
  c.face(0, i, j);
  return c;
}
Config coplanar_shared_vertex_overlap() {  // (3,1) is inside face 0
  return coplanar_shared_vertex({3, 1, 0}, {1, 4, 0}).pair(0, 1, Kind::touching);
}
Config coplanar_shared_vertex_apart() {  // face 1 spans 104 to 166 degrees
  return coplanar_shared_vertex({-4, 1, 0}, {-1, 4, 0});
}
Config coplanar_shared_vertex_collinear_edges() {  // both have an edge along +x: [0,2] shared
  return coplanar_shared_vertex({2, -2, 0}, {2, 0, 0}).pair(0, 1, Kind::touching);
}
Config coplanar_shared_vertex_opposite_edges() {  // edges along +x and -x: only the vertex
  return coplanar_shared_vertex({-2, 0, 0}, {-2, -2, 0});
}
// The plane z = x + 2y: exactly coplanar but not axis-aligned (integer images of (x, y, 0)).
Config coplanar_overlap_tilted() {
  Config c;
  c.tri({0, 0, 0}, {4, 0, 4}, {0, 4, 8});
  c.tri({1, 1, 3}, {5, 1, 7}, {1, 5, 11});
  return c.pair(0, 1, Kind::touching);
}
Config coplanar_shared_edge_folded_tilted() {
  Config c;
  c.vertex({0, 0, 0});
  c.vertex({4, 0, 4});
  c.vertex({1, 3, 7});
  c.vertex({3, 2, 7});
  c.face(0, 1, 2);
  c.face(1, 0, 3);
  return c.pair(0, 1, Kind::touching);
}

// ---------------------------------------------------------------------------------------------
// Non-coplanar contacts between faces that share no vertex; face 0 is t0() unless noted.

Config vertex_on_face() {  // (1,1,0) inside face 0; the rest of face 1 at z = 3
  Config c = t0();
  c.tri({1, 1, 0}, {2, 1, 3}, {1, 2, 3});
  return c.pair(0, 1, Kind::touching);
}
// Face 0 in the plane x + y + z = 4; vertex 3 (1,1,2) inside it (barycentric 1/4 1/4 1/2);
// the other corners of face 1 have x + y + z = 10 and 9. Face 1's plane is z - x = 1, which
// face 0's corners straddle (-5, -1, 3), far from any ulp.
Config vertex_on_face_tilted() {
  Config c;
  c.tri({4, 0, 0}, {0, 4, 0}, {0, 0, 4});
  c.tri({1, 1, 2}, {3, 3, 4}, {2, 4, 3});
  return c.pair(0, 1, Kind::touching);
}
Config vertex_on_edge() {  // face 1 in the plane x = 2, touching z = 0 only at (2,0,0)
  Config c = t0();
  c.tri({2, 0, 0}, {2, -1, 3}, {2, 1, 3});
  return c.pair(0, 1, Kind::touching);
}
// Face 0 (0,0,0) (4,4,0) (0,4,0); vertex 3 (2,2,0) on its edge y = x, the rest of face 1 at
// z = 3. Moving x of vertex 3 down puts it inside face 0, up puts it outside.
Config vertex_on_edge_diagonal() {
  Config c;
  c.tri({0, 0, 0}, {4, 4, 0}, {0, 4, 0});
  c.tri({2, 2, 0}, {3, 1, 3}, {1, 3, 3});
  return c.pair(0, 1, Kind::touching);
}
Config vertex_on_vertex() {  // vertex 3 has vertex 1's position (another id)
  Config c = t0();
  c.tri({4, 0, 0}, {5, 0, 3}, {5, 1, 3});
  return c.pair(0, 1, Kind::touching);
}
// Face 1 in the plane x = 2; its edge (2,1,-1)-(2,-1,1) crosses z = 0 at its midpoint (2,0,0),
// on face 0's edge y = 0; face 1 meets z = 0 along y in [-2, 0] only. Both straddle the other's
// plane but share a point: touching. Moving y of vertex 3 by d moves the crossing to y = d/2.
Config edge_through_edge() {
  Config c = t0();
  c.tri({2, 1, -1}, {2, -1, 1}, {2, -3, -1});
  return c.pair(0, 1, Kind::touching);
}
// The same sheared by z -> x + y + z: face 0 in the plane z = x + y (region x, y >= 0,
// x + y <= 4 there); face 1's edge (2,1,2)-(2,-1,2) meets it at (2,0,2), on face 0's edge.
// Moving x of vertex 3 by d puts the meeting point at y = -d/(2+d) (d < 0: inside, crossing;
// d > 0: outside, none). Moving y of vertex 3 keeps that edge at x = 2, z = 2, so it still
// meets the plane at y = 0: still touching.
Config edge_through_edge_tilted() {
  Config c;
  c.tri({0, 0, 0}, {4, 0, 4}, {0, 4, 4});
  c.tri({2, 1, 2}, {2, -1, 2}, {2, -3, -2});
  return c.pair(0, 1, Kind::touching);
}
Config edge_on_face() {  // face 1's edge (1,1,0)-(2,1,0) lies inside face 0; face 1 above
  Config c = t0();
  c.tri({1, 1, 0}, {2, 1, 0}, {1, 1, 3});
  return c.pair(0, 1, Kind::touching);
}
Config edge_along_edge() {  // face 1's edge [1,3] on y = 0 lies on face 0's edge; not coplanar
  Config c = t0();
  c.tri({1, 0, 0}, {3, 0, 0}, {2, -1, 3});
  return c.pair(0, 1, Kind::touching);
}
Config crossing() {  // face 1 (plane y = 1) crosses face 0 along (1,1,0)-(2,1,0)
  Config c = t0();
  c.tri({1, 1, -1}, {1, 1, 1}, {3, 1, -1});
  return c.pair(0, 1, Kind::crossing);
}
// Face 1 in the plane x = y with a corner (-2,-2,0) in z = 0 outside face 0; it meets z = 0
// along (-2,-2)-(1,1), which crosses face 0 from its corner (0,0) to (1,1).
Config crossing_through_corner() {
  Config c = t0();
  c.tri({1, 1, -2}, {1, 1, 2}, {-2, -2, 0});
  return c.pair(0, 1, Kind::crossing);
}

// ---------------------------------------------------------------------------------------------
// Non-coplanar faces sharing vertex 0.

Config shared_vertex(P3 a0, P3 a1, P3 a2, P3 b1, P3 b2) {
  Config c;
  c.vertex(a0);
  c.vertex(a1);
  c.vertex(a2);
  c.face(0, 1, 2);
  const int i = c.vertex(b1), j = c.vertex(b2);
  c.face(0, i, j);
  return c;
}
// Face 1's opposite edge (2,1,1)-(1,2,-1) pierces face 0 at (1.5,1.5,0); face 1's plane
// -x + y + z = 0 has face 0's corners at -4 and 4.
Config shared_vertex_piercing() {
  return shared_vertex({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {2, 1, 1}, {1, 2, -1})
      .pair(0, 1, Kind::crossing);
}
Config shared_vertex_apart() {  // face 1's plane -x - y + z = 0 has face 0's corners at -4, -4
  return shared_vertex({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {-1, 2, 1}, {-2, 1, -1});
}
// Plane z = 1: face 1's edge from vertex 0 to vertex 3 (2,1,1) lies inside face 0, its third
// corner is at z = 4. Moving z of vertex 3 down makes face 1 cross z = 1 along a segment from
// vertex 0 into face 0 (crossing); up leaves vertex 0 as the only contact (none).
Config shared_vertex_edge_in_plane() {
  return shared_vertex({0, 0, 1}, {4, 0, 1}, {0, 4, 1}, {2, 1, 1}, {1, 1, 4})
      .pair(0, 1, Kind::touching);
}
Config shared_vertex_edge_in_plane_through() {  // edge to (4,2,0) leaves face 0 at (8/3,4/3,0)
  return shared_vertex({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {4, 2, 0}, {1, 1, 3})
      .pair(0, 1, Kind::touching);
}
Config shared_vertex_edge_in_plane_outside() {  // edge to (-2,1,0) is outside face 0's angle
  return shared_vertex({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {-2, 1, 0}, {-1, -1, 3});
}
// Plane z = 1: face 1 (plane y = z - 1) crosses z = 1 along face 0's edge from vertex 0 to
// (2,0,1), the midpoint of its edge (2,1,2)-(2,-1,0); face 0 lies on one side of face 1's plane:
// touching. Moving y of vertex 3 by d moves that midpoint to y = d/2 (inside face 0 for d > 0:
// crossing; outside for d < 0: none).
Config shared_vertex_edge_on_edge() {
  return shared_vertex({0, 0, 1}, {4, 0, 1}, {0, 4, 1}, {2, 1, 2}, {2, -1, 0})
      .pair(0, 1, Kind::touching);
}
Config shared_vertex_edge_along_edge() {  // face 1's edge [0,2] on y = 0 lies on face 0's edge
  return shared_vertex({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {2, 0, 0}, {1, -1, 3})
      .pair(0, 1, Kind::touching);
}
Config shared_vertex_edge_along_edge_opposite() {  // face 1's edge goes along -x: vertex only
  return shared_vertex({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {-2, 0, 0}, {-1, -1, 3});
}
Config shared_edge_bent() {  // shared edge, a sharp fold (third corner (2,1,3) over face 0)
  Config c;
  c.vertex({0, 0, 0});
  c.vertex({4, 0, 0});
  c.vertex({1, 3, 0});
  c.vertex({2, 1, 3});
  c.face(0, 1, 2);
  c.face(1, 0, 3);
  return c;
}

// ---------------------------------------------------------------------------------------------
// Slivers (h = 2^-40).

Config sliver_needle_crossed() {  // needle (0,0)-(4,0)-(4,h); face 1 (x = 2) meets it on [0,h/2]
  Config c;
  c.tri({0, 0, 0}, {4, 0, 0}, {4, kH, 0});
  c.tri({2, -1, -1}, {2, 1, -1}, {2, 0, 1});
  return c.pair(0, 1, Kind::crossing);
}
Config sliver_needle_piercing() {  // needle in y = 1 crossing z = 0 along (1,1)-(1+h/2,1)
  Config c = t0();
  c.tri({1, 1, -1}, {1, 1, 1}, {1 + kH, 1, 1});
  return c.pair(0, 1, Kind::crossing);
}
Config sliver_needle_touch() {  // needle crossing z = 0 along (3,1)-(3+h/2,1): only (3,1) is in
  Config c = t0();
  c.tri({3, 1, -1}, {3, 1, 1}, {3 + kH, 1, 1});
  return c.pair(0, 1, Kind::touching);
}
Config sliver_needle_near_miss() {  // the same at y = 1 + 2^-50: x + y > 4 all along
  Config c = t0();
  const double y = 1 + std::ldexp(1.0, -50);
  c.tri({3, y, -1}, {3, y, 1}, {3 + kH, y, 1});
  return c;
}
Config sliver_obtuse_crossed() {  // apex angle near 180 degrees; face 1 (x = 3) meets it
  Config c;
  c.tri({0, 0, 0}, {8, 0, 0}, {4, kH, 0});
  c.tri({3, -1, -1}, {3, 1, -1}, {3, 0, 1});
  return c.pair(0, 1, Kind::crossing);
}
// Coplanar: face 1 stands on face 0's apex (4,h,0) with its own vertex 3 there. Moving y of
// vertex 3 down puts it inside face 0 (overlap), up lifts face 1 off it.
Config sliver_obtuse_apex_touch() {
  Config c;
  c.tri({0, 0, 0}, {8, 0, 0}, {4, kH, 0});
  c.tri({4, kH, 0}, {6, 1, 0}, {2, 1, 0});
  return c.pair(0, 1, Kind::touching);
}
// Apex height 2^-1074 (the smallest subnormal): area 2^-1072, not zero. Face 1 in the plane
// x = 4 meets it along (4,0,0)-(4,2^-1074,0); corners of face 0 at x - 4 = -4, 4, 0.
Config sliver_obtuse_denormal_crossed() {
  Config c;
  c.tri({0, 0, 0}, {8, 0, 0}, {4, std::numeric_limits<double>::denorm_min(), 0});
  c.tri({4, -1, -1}, {4, 1, -1}, {4, 0, 1});
  return c.pair(0, 1, Kind::crossing);
}

// ---------------------------------------------------------------------------------------------
// Zero-area faces.

// Face 1 (0,0,-2) (1,1,0) (2,2,2) is collinear and passes through face 0 at (1,1,0); face 2
// (plane y = 1) crosses face 0 along (2,1,0)-(2.5,1,0).
Config zero_area_collinear() {
  Config c = t0();
  c.tri({0, 0, -2}, {1, 1, 0}, {2, 2, 2});
  c.tri({2, 1, -1}, {2, 1, 1}, {3, 1, -1});
  c.degenerate = {1};
  return c.pair(0, 2, Kind::crossing);
}
// The same with z of vertex 5 one ulp up: face 1 is a sliver in the plane x = y, crossing z = 0
// from (1,1,0) to a point on its edge (0,0,-2)-(2,2,2+u) just short of (1,1,0).
Config zero_area_near_collinear() {
  Config c = zero_area_collinear();
  c.degenerate.clear();
  c.nudge(5, Z, +1);
  return c.expect({{0, 1, Kind::crossing}, {0, 2, Kind::crossing}});
}
Config zero_area_repeated_index() {  // face 1 is `f 4 4 5`: two corners name vertex 3
  Config c = t0();
  c.vertex({1, 1, -1});
  c.vertex({1, 1, 1});
  c.face(3, 3, 4);
  c.tri({2, 1, -1}, {2, 1, 1}, {3, 1, -1});
  c.degenerate = {1};
  return c.pair(0, 2, Kind::crossing);
}
// Face 0 (collinear) and face 3 (repeated index) come first and use the edges of face 1, whose
// edge (1,1,-1)-(1,1,1) pierces face 2 (= t0()): the pair must survive the degenerate faces
// taking part in edge ownership.
Config zero_area_owns_edges() {
  Config c;
  c.vertex({1, 1, -1});
  c.vertex({1, 1, 1});
  c.vertex({1, 1, 3});
  c.vertex({3, 1, -1});
  c.face(0, 1, 2);
  c.face(1, 0, 3);
  c.tri({0, 0, 0}, {4, 0, 0}, {0, 4, 0});
  c.face(3, 1, 3);
  c.degenerate = {0, 3};
  return c.pair(1, 2, Kind::crossing);
}

// ---------------------------------------------------------------------------------------------
// Duplicated faces and vertices.

Config duplicate_face(bool reversed) {  // faces 0 and 1 name the same three vertices
  Config c = t0();
  if (reversed)
    c.face(0, 2, 1);
  else
    c.face(0, 1, 2);
  c.tri({1, 1, -1}, {1, 1, 1}, {3, 1, -1});  // crosses both, as in crossing()
  return c.expect({{0, 1, Kind::touching}, {0, 2, Kind::crossing}, {1, 2, Kind::crossing}});
}
// Face 1 uses vertices 3 and 4, copies of vertices 1 and 2; face 1 = (3,5,4), after a weld
// (1,5,2), the opposite orientation of the shared edge.
Config duplicate_vertices_quad(P3 third) {
  Config c = t0();
  c.vertex({4, 0, 0});
  c.vertex({0, 4, 0});
  c.vertex(third);
  c.face(3, 5, 4);
  return c;
}
Config duplicate_vertex_pair(P3 a1, P3 a2, P3 b1, P3 b2) {  // vertex 3 is a copy of vertex 0
  Config c;
  c.vertex({0, 0, 0});
  c.vertex(a1);
  c.vertex(a2);
  c.face(0, 1, 2);
  c.vertex({0, 0, 0});
  c.vertex(b1);
  c.vertex(b2);
  c.face(3, 4, 5);
  return c;
}
// Face 0 (2,0,0) (2,4,0) (0,2,0) lies in x <= 2. Face 1 = (3,4,5): vertex 3 is a copy of
// vertex 1 (2,4,0); vertex 4 is (2,0,0) moved one ulp in x; vertex 5 is (4,2,0).
Config near_duplicate_seam(int direction) {
  Config c;
  c.tri({2, 0, 0}, {2, 4, 0}, {0, 2, 0});
  c.vertex({2, 4, 0});
  c.vertex({2, 0, 0});
  c.vertex({4, 2, 0});
  c.face(3, 4, 5);
  c.nudge(4, X, direction);
  return c;
}

// ---------------------------------------------------------------------------------------------
// Assembly.

Config with_nudge(Config c, int vertex_id, int axis, int direction, std::vector<Pair> pairs) {
  c.nudge(vertex_id, axis, direction);
  return c.expect(std::move(pairs));
}
std::vector<Pair> none() {
  return {};
}
std::vector<Pair> one(Kind kind) {
  return {{0, 1, kind}};
}

/// Whole meshes: the parts side by side, part k moved by 16 k along x (every part fits in
/// x in [-6, 8], so parts are at least 2 apart and never meet).
Config combine(const std::vector<Config>& parts) {
  Config out;
  for (size_t k = 0; k < parts.size(); ++k) {
    const Config& part = parts[k];
    const int v0 = static_cast<int>(out.v.size()), f0 = static_cast<int>(out.f.size());
    for (P3 p : part.v) {
      if (p[0] < -6 || p[0] > 8) throw std::logic_error("combine: a part is wider than 14");
      p[0] += 16.0 * static_cast<double>(k);
      out.v.push_back(p);
    }
    for (const auto& face : part.f) out.f.push_back({face[0] + v0, face[1] + v0, face[2] + v0});
    for (const Pair& p : part.pairs) out.pairs.push_back({p.a + f0, p.b + f0, p.kind});
    for (int d : part.degenerate) out.degenerate.push_back(d + f0);
    for (const Nudge& n : part.nudges) out.nudges.push_back({n.vertex + v0, n.axis, n.direction});
  }
  return out;
}

/// x -> x * scale + offset on every coordinate; throws unless every result is exact.
Config transformed(Config c, double scale, double offset) {
  for (P3& p : c.v)
    for (double& x : p) {
      const double product = x * scale;
      if (std::fma(x, scale, -product) != 0) throw std::logic_error("inexact scale");
      const double sum = product + offset;
      // Knuth's two-sum: the rounding error of product + offset, zero when the sum is exact.
      const double b = sum - product;
      if ((product - (sum - b)) + (offset - b) != 0) throw std::logic_error("inexact offset");
      x = sum;
    }
  return c;
}

std::vector<Config> combo_parts() {
  return {coplanar_overlap(),
          coplanar_inside(),
          coplanar_apart(),
          coplanar_edges_overlap(),
          coplanar_shared_edge_folded(),
          coplanar_shared_edge_flat(),
          coplanar_shared_vertex_overlap(),
          coplanar_shared_vertex_apart(),
          coplanar_shared_vertex_collinear_edges(),
          coplanar_shared_vertex_opposite_edges(),
          vertex_on_face(),
          vertex_on_edge(),
          vertex_on_vertex(),
          edge_through_edge(),
          edge_on_face(),
          edge_along_edge(),
          crossing(),
          crossing_through_corner(),
          shared_vertex_piercing(),
          shared_vertex_apart(),
          shared_vertex_edge_in_plane(),
          shared_vertex_edge_in_plane_through(),
          shared_vertex_edge_in_plane_outside(),
          shared_vertex_edge_on_edge(),
          shared_vertex_edge_along_edge(),
          shared_vertex_edge_along_edge_opposite(),
          shared_edge_bent()};
}

// The one-ulp configurations, each named once here and used both alone and in combo_near.
struct Near {
  std::string name;
  std::string description;
  Config mesh;
};

std::vector<Near> near_cases() {
  const Kind c = Kind::crossing, t = Kind::touching;
  return {
      {"coplanar_vertex_on_edge_ulp_toward",
       "coplanar_vertex_on_edge with x of vertex 3 one ulp down: it is inside face 0 and the "
       "faces overlap",
       with_nudge(coplanar_vertex_on_edge(), 3, X, -1, one(t))},
      {"coplanar_vertex_on_edge_ulp_away",
       "coplanar_vertex_on_edge with x of vertex 3 one ulp up: face 1 lies strictly in y < x",
       with_nudge(coplanar_vertex_on_edge(), 3, X, +1, none())},
      {"coplanar_shared_edge_folded_ulp_up",
       "coplanar_shared_edge_folded with z of vertex 3 one ulp up: no longer coplanar; faces "
       "sharing an edge then meet only on it",
       with_nudge(coplanar_shared_edge_folded(), 3, Z, +1, none())},
      {"coplanar_shared_edge_folded_ulp_down",
       "coplanar_shared_edge_folded with z of vertex 3 one ulp down: not coplanar",
       with_nudge(coplanar_shared_edge_folded(), 3, Z, -1, none())},
      {"coplanar_shared_edge_flat_ulp_down",
       "coplanar_shared_edge_flat with z of vertex 3 one ulp down: not coplanar",
       with_nudge(coplanar_shared_edge_flat(), 3, Z, -1, none())},
      {"vertex_on_face_tilted_ulp_toward",
       "vertex_on_face_tilted with z of vertex 3 one ulp down (x + y + z < 4): face 1 crosses "
       "face 0 along a segment next to (1 1 2)",
       with_nudge(vertex_on_face_tilted(), 3, Z, -1, one(c))},
      {"vertex_on_face_tilted_ulp_away",
       "vertex_on_face_tilted with z of vertex 3 one ulp up: face 1 is strictly on one side",
       with_nudge(vertex_on_face_tilted(), 3, Z, +1, none())},
      {"vertex_on_edge_diagonal_ulp_inside",
       "vertex_on_edge_diagonal with x of vertex 3 one ulp down: the vertex is inside face 0",
       with_nudge(vertex_on_edge_diagonal(), 3, X, -1, one(t))},
      {"vertex_on_edge_diagonal_ulp_outside",
       "vertex_on_edge_diagonal with x of vertex 3 one ulp up: the vertex is outside face 0 "
       "and face 1 meets z = 0 nowhere else",
       with_nudge(vertex_on_edge_diagonal(), 3, X, +1, none())},
      {"edge_through_edge_ulp_toward",
       "edge_through_edge with y of vertex 3 one ulp up: the edge crosses z = 0 at y = 2^-53 "
       "inside face 0",
       with_nudge(edge_through_edge(), 3, Y, +1, one(c))},
      {"edge_through_edge_ulp_away",
       "edge_through_edge with y of vertex 3 one ulp down: the edge crosses z = 0 at y < 0",
       with_nudge(edge_through_edge(), 3, Y, -1, none())},
      {"edge_through_edge_tilted_ulp_toward",
       "edge_through_edge_tilted with x of vertex 3 one ulp down: the edge meets face 0's plane "
       "inside it",
       with_nudge(edge_through_edge_tilted(), 3, X, -1, one(c))},
      {"edge_through_edge_tilted_ulp_away",
       "edge_through_edge_tilted with x of vertex 3 one ulp up: the edge meets face 0's plane "
       "outside it",
       with_nudge(edge_through_edge_tilted(), 3, X, +1, none())},
      {"edge_through_edge_tilted_ulp_along",
       "edge_through_edge_tilted with y of vertex 3 one ulp up: the edge stays at x = 2 z = 2 "
       "and still meets face 0's edge exactly at (2 0 2)",
       with_nudge(edge_through_edge_tilted(), 3, Y, +1, one(t))},
      {"shared_vertex_edge_in_plane_ulp_toward",
       "shared_vertex_edge_in_plane with z of vertex 3 one ulp down: face 1 crosses z = 1 along "
       "a segment from vertex 0 into face 0",
       with_nudge(shared_vertex_edge_in_plane(), 3, Z, -1, one(c))},
      {"shared_vertex_edge_in_plane_ulp_away",
       "shared_vertex_edge_in_plane with z of vertex 3 one ulp up: face 1 meets z = 1 only at "
       "the shared vertex",
       with_nudge(shared_vertex_edge_in_plane(), 3, Z, +1, none())},
      {"shared_vertex_edge_on_edge_ulp_toward",
       "shared_vertex_edge_on_edge with y of vertex 3 one ulp up: face 1 crosses z = 1 from "
       "vertex 0 to (2 2^-53 1) inside face 0",
       with_nudge(shared_vertex_edge_on_edge(), 3, Y, +1, one(c))},
      {"shared_vertex_edge_on_edge_ulp_away",
       "shared_vertex_edge_on_edge with y of vertex 3 one ulp down: face 1 crosses z = 1 from "
       "vertex 0 to (2 -2^-54 1) outside face 0",
       with_nudge(shared_vertex_edge_on_edge(), 3, Y, -1, none())},
  };
}

std::vector<Config> combo_near_parts() {
  std::vector<Config> parts = {
      coplanar_vertex_on_edge(), coplanar_overlap_tilted(), coplanar_shared_edge_folded_tilted(),
      vertex_on_face_tilted(),   vertex_on_edge_diagonal(), edge_through_edge_tilted()};
  for (const Near& n : near_cases()) parts.push_back(n.mesh);
  return parts;
}

std::vector<Case> make_cases() {
  const Kind c = Kind::crossing, t = Kind::touching;
  std::vector<Case> cases = {
      {"coplanar_overlap", "coplanar triangles in z = 0 overlapping with positive area",
       coplanar_overlap()},
      {"coplanar_inside", "coplanar triangle strictly inside another: no edges cross",
       coplanar_inside()},
      {"coplanar_apart", "coplanar triangles whose boxes overlap; face 1 lies in x + y >= 5",
       coplanar_apart()},
      {"coplanar_edges_overlap",
       "coplanar triangles on either side of collinear edges overlapping on [1 4]",
       coplanar_edges_overlap()},
      {"coplanar_vertex_on_edge",
       "coplanar; vertex 3 exactly on face 0's diagonal edge y = x; face 1 on the other side",
       coplanar_vertex_on_edge()},
      {"coplanar_shared_edge_folded",
       "shared edge; coplanar in z = 1 with both third corners on one side: folded flat",
       coplanar_shared_edge_folded()},
      {"coplanar_shared_edge_flat",
       "shared edge; coplanar with third corners on opposite sides: a flat mesh",
       coplanar_shared_edge_flat()},
      {"coplanar_shared_vertex_overlap", "shared vertex; coplanar; the faces' angles overlap",
       coplanar_shared_vertex_overlap()},
      {"coplanar_shared_vertex_apart", "shared vertex; coplanar; the faces' angles are apart",
       coplanar_shared_vertex_apart()},
      {"coplanar_shared_vertex_collinear_edges",
       "shared vertex; coplanar; an edge of each leaves it along +x: they share [0 2] of it",
       coplanar_shared_vertex_collinear_edges()},
      {"coplanar_shared_vertex_opposite_edges",
       "shared vertex; coplanar; edges leave it along +x and -x: they meet only at the vertex",
       coplanar_shared_vertex_opposite_edges()},
      {"coplanar_overlap_tilted", "coplanar_overlap mapped into the plane z = x + 2y",
       coplanar_overlap_tilted()},
      {"coplanar_shared_edge_folded_tilted",
       "coplanar_shared_edge_folded mapped into the plane z = x + 2y",
       coplanar_shared_edge_folded_tilted()},
      {"vertex_on_face", "vertex (1 1 0) of face 1 exactly inside face 0; face 1 above it",
       vertex_on_face()},
      {"vertex_on_face_denormal_toward",
       "vertex_on_face with z of vertex 3 one ulp down (-2^-1074): face 1 crosses face 0 along "
       "a segment of subnormal length",
       with_nudge(vertex_on_face(), 3, Z, -1, one(c))},
      {"vertex_on_face_denormal_away",
       "vertex_on_face with z of vertex 3 one ulp up (2^-1074): face 1 is strictly above",
       with_nudge(vertex_on_face(), 3, Z, +1, none())},
      {"vertex_on_face_tilted",
       "vertex (1 1 2) of face 1 exactly inside face 0 in the plane x + y + z = 4",
       vertex_on_face_tilted()},
      {"vertex_on_edge", "vertex (2 0 0) of face 1 exactly on face 0's edge", vertex_on_edge()},
      {"vertex_on_edge_diagonal", "vertex (2 2 0) of face 1 exactly on face 0's edge y = x",
       vertex_on_edge_diagonal()},
      {"vertex_on_vertex", "vertex 3 of face 1 at vertex 1's position (distinct ids)",
       vertex_on_vertex()},
      {"edge_through_edge",
       "an edge of face 1 exactly through face 0's edge at (2 0 0); each straddles the other's "
       "plane but they share one point",
       edge_through_edge()},
      {"edge_through_edge_tilted",
       "edge_through_edge sheared into face 0's plane z = x + y: contact at (2 0 2)",
       edge_through_edge_tilted()},
      {"edge_on_face", "an edge of face 1 lies inside face 0; face 1 above", edge_on_face()},
      {"edge_along_edge",
       "an edge of face 1 lies on face 0's edge (collinear overlap); not coplanar",
       edge_along_edge()},
      {"crossing", "face 1 passes through face 0's interior", crossing()},
      {"crossing_through_corner",
       "face 1 crosses face 0 from face 0's corner (0 0 0) to (1 1 0); face 1 has a corner in "
       "face 0's plane outside it",
       crossing_through_corner()},
      {"shared_vertex_piercing", "shared vertex; face 1's opposite edge pierces face 0",
       shared_vertex_piercing()},
      {"shared_vertex_apart", "shared vertex; face 0 is on one side of face 1's plane",
       shared_vertex_apart()},
      {"shared_vertex_edge_in_plane",
       "shared vertex; an edge of face 1 lies in face 0's plane inside face 0's angle",
       shared_vertex_edge_in_plane()},
      {"shared_vertex_edge_in_plane_through",
       "shared vertex; an edge of face 1 in face 0's plane runs through face 0 and out of it",
       shared_vertex_edge_in_plane_through()},
      {"shared_vertex_edge_in_plane_outside",
       "shared vertex; an edge of face 1 in face 0's plane outside face 0's angle",
       shared_vertex_edge_in_plane_outside()},
      {"shared_vertex_edge_on_edge",
       "shared vertex; face 1 passes through face 0's plane exactly along face 0's edge",
       shared_vertex_edge_on_edge()},
      {"shared_vertex_edge_along_edge",
       "shared vertex; an edge of face 1 lies along face 0's edge from that vertex",
       shared_vertex_edge_along_edge()},
      {"shared_vertex_edge_along_edge_opposite",
       "shared vertex; an edge of face 1 continues face 0's edge the other way",
       shared_vertex_edge_along_edge_opposite()},
      {"shared_edge_bent", "shared edge; not coplanar (a sharp fold)", shared_edge_bent()},
      {"sliver_needle_crossed", "needle face 0 (angle 2^-42 rad) crossed by face 1",
       sliver_needle_crossed()},
      {"sliver_needle_piercing", "needle face 1 (angle about 2^-41 rad) piercing face 0",
       sliver_needle_piercing()},
      {"sliver_needle_touch",
       "needle face 1 whose long edge passes exactly through face 0's edge at (3 1 0) and "
       "whose tip lies outside",
       sliver_needle_touch()},
      {"sliver_needle_near_miss", "sliver_needle_touch moved 2^-50 off face 0 in y",
       sliver_needle_near_miss()},
      {"sliver_obtuse_crossed", "face 0 with an apex angle near 180 degrees crossed by face 1",
       sliver_obtuse_crossed()},
      {"sliver_obtuse_apex_touch",
       "coplanar; face 1 stands with its vertex exactly on face 0's flat apex (4 2^-40 0)",
       sliver_obtuse_apex_touch()},
      {"sliver_obtuse_apex_touch_ulp_overlap",
       "sliver_obtuse_apex_touch with y of vertex 3 one ulp down: inside face 0",
       with_nudge(sliver_obtuse_apex_touch(), 3, Y, -1, one(t))},
      {"sliver_obtuse_apex_touch_ulp_apart",
       "sliver_obtuse_apex_touch with y of vertex 3 one ulp up: above face 0's apex",
       with_nudge(sliver_obtuse_apex_touch(), 3, Y, +1, none())},
      {"sliver_obtuse_denormal_crossed",
       "face 0 of apex height 2^-1074 (area 2^-1072: not zero) crossed by face 1 in the plane "
       "through its apex",
       sliver_obtuse_denormal_crossed()},
      {"zero_area_collinear",
       "face 1 has collinear corners through face 0 (degenerate); face 2 crosses face 0",
       zero_area_collinear()},
      {"zero_area_near_collinear",
       "zero_area_collinear with z of vertex 5 one ulp up: face 1 is a sliver crossing face 0",
       zero_area_near_collinear()},
      {"zero_area_repeated_index", "face 1 repeats a vertex index (f 4 4 5); face 2 crosses face 0",
       zero_area_repeated_index()},
      {"zero_area_owns_edges",
       "degenerate faces 0 (collinear) and 3 (repeated index) share edges with face 1; face 1 "
       "crosses face 2",
       zero_area_owns_edges()},
      {"duplicate_face",
       "faces 0 and 1 name the same vertices in the same order; face 2 "
       "crosses both",
       duplicate_face(false)},
      {"duplicate_face_reversed",
       "faces 0 and 1 name the same vertices in opposite orders; "
       "face 2 crosses both",
       duplicate_face(true)},
  };
  for (Near& n : near_cases()) cases.push_back({n.name, n.description, n.mesh});

  // Duplicated vertices: the same file without a weld and with one.
  cases.push_back(
      {"duplicate_vertices_seam",
       "a flat quad whose diagonal's two vertices are listed twice: without a weld the faces "
       "touch along it; welded they share the edge",
       duplicate_vertices_quad({4, 4, 0}),
       {{"", "", one(t)}, {"_weld0", "0", none()}}});
  cases.push_back({"duplicate_vertices_folded",
                   "the quad folded flat (third corner (1 2 0) inside face 0) with the shared "
                   "edge's vertices listed twice",
                   duplicate_vertices_quad({1, 2, 0}),
                   {{"", "", one(t)}, {"_weld0", "0", one(t)}}});
  cases.push_back({"duplicate_vertex_fan",
                   "coplanar_shared_vertex_apart with the shared vertex listed twice: they "
                   "touch at it unless welded",
                   duplicate_vertex_pair({4, 0, 0}, {4, 2, 0}, {-4, 1, 0}, {-1, 4, 0}),
                   {{"", "", one(t)}, {"_weld0", "0", none()}}});
  cases.push_back({"duplicate_vertex_piercing",
                   "shared_vertex_piercing with the shared vertex listed twice: crossing "
                   "either way",
                   duplicate_vertex_pair({4, 0, 0}, {0, 4, 0}, {2, 1, 1}, {1, 2, -1}),
                   {{"", "", one(c)}, {"_weld0", "0", one(c)}}});
  cases.push_back({"near_duplicate_seam_away",
                   "a flat quad whose diagonal (2 0 0)-(2 4 0) has (2 4 0) listed twice and "
                   "(2 0 0) copied one ulp up in x (face 1 leans away): they touch at (2 4 0); "
                   "--weld 0 joins only the exact copy; --weld 1e-9 joins both",
                   near_duplicate_seam(+1),
                   {{"", "", one(t)}, {"_weld0", "0", none()}, {"_weld1e-9", "1e-9", none()}}});
  cases.push_back({"near_duplicate_seam_overlap",
                   "near_duplicate_seam_away with the copy one ulp down in x: face 1's edge from "
                   "(2 4 0) runs into face 0",
                   near_duplicate_seam(-1),
                   {{"", "", one(t)}, {"_weld0", "0", one(t)}, {"_weld1e-9", "1e-9", none()}}});

  // Whole meshes, offset and scaled. Every coordinate of combo is an integer below 512 and
  // every contact in it is exact after each transform (checked by `transformed`); in the
  // decimal 1e-6 scaling, the coordinates that meet are the same decimal, its negation, or
  // twice it, and the rest have margins far above a rounding, as argued per part below.
  const Config combo = combine(combo_parts());
  const std::string combo_text =
      "the exact contacts of " + std::to_string(combo_parts().size()) +
      " cases side by side (part k moved by 16k in x): coplanar_overlap coplanar_inside "
      "coplanar_apart coplanar_edges_overlap coplanar_shared_edge_folded "
      "coplanar_shared_edge_flat coplanar_shared_vertex_overlap coplanar_shared_vertex_apart "
      "coplanar_shared_vertex_collinear_edges coplanar_shared_vertex_opposite_edges "
      "vertex_on_face vertex_on_edge vertex_on_vertex edge_through_edge edge_on_face "
      "edge_along_edge crossing crossing_through_corner shared_vertex_piercing "
      "shared_vertex_apart shared_vertex_edge_in_plane shared_vertex_edge_in_plane_through "
      "shared_vertex_edge_in_plane_outside shared_vertex_edge_on_edge "
      "shared_vertex_edge_along_edge shared_vertex_edge_along_edge_opposite shared_edge_bent";
  cases.push_back({"combo", combo_text, combo});
  const double e6 = 1e6, e9 = 1e9, p30 = std::ldexp(1.0, 30), m20 = std::ldexp(1.0, -20);
  cases.push_back(
      {"combo_offset_1e6", "combo + 1e6 on every coordinate (exact)", transformed(combo, 1, e6)});
  cases.push_back({"combo_offset_1e9", "combo + 1e9 on every coordinate (exact: integers)",
                   transformed(combo, 1, e9)});
  cases.push_back({"combo_offset_2p30", "combo + 2^30 on every coordinate (exact)",
                   transformed(combo, 1, p30)});
  cases.push_back({"combo_scale_1e6", "combo * 1e6 (exact: integers)", transformed(combo, e6, 0)});
  cases.push_back(
      {"combo_scale_2m20", "combo * 2^-20 (about 9.5e-7; exact)", transformed(combo, m20, 0)});
  // Decimal 1e-6: coordinate N is written "Ne-6" and read as the double nearest N / 10^6, so
  // values are not exact multiples. The contacts of combo survive because rounding to nearest
  // is monotone and odd and commutes with doubling: contacts on y = 0 or z = 0 stay there; a
  // plane z = 1 stays the one double for "1e-6"; the midpoint of (y, z) = (1e-6, 2e-6) and
  // (-1e-6, 0) is still at y = 0 z = 1e-6 (shared_vertex_edge_on_edge), and of (1e-6, -1e-6)
  // and (-1e-6, 1e-6) at y = z = 0 (edge_through_edge); shared vertices keep their ids; every
  // other relation holds with a margin of at least 1e-6 against roundings near 1e-22. Only
  // crossing_through_corner's contact with face 0's corner may be lost: face 1 still crosses
  // face 0 along a segment of length near 1.4e-6 from near that corner, so it is still
  // crossing.
  Case micro{"combo_scale_1em6", "combo * 1e-6 written in decimal (Ne-6); same pairs", combo};
  micro.decimal_micro = true;
  cases.push_back(micro);

  const Config near = combine(combo_near_parts());
  const std::string near_text =
      "coplanar_vertex_on_edge coplanar_overlap_tilted coplanar_shared_edge_folded_tilted "
      "vertex_on_face_tilted vertex_on_edge_diagonal edge_through_edge_tilted and the " +
      std::to_string(near_cases().size()) +
      " one-ulp cases (*_ulp_*) side by side (part k moved by 16k in x); each ulp is taken "
      "after the transform";
  cases.push_back({"combo_near", near_text, near});
  cases.push_back(
      {"combo_near_offset_1e6", "combo_near + 1e6 on every coordinate", transformed(near, 1, e6)});
  cases.push_back(
      {"combo_near_offset_1e9", "combo_near + 1e9 on every coordinate", transformed(near, 1, e9)});
  cases.push_back({"combo_near_offset_2p30", "combo_near + 2^30 on every coordinate",
                   transformed(near, 1, p30)});
  cases.push_back({"combo_near_scale_1e6", "combo_near * 1e6", transformed(near, e6, 0)});
  cases.push_back({"combo_near_scale_2m20", "combo_near * 2^-20", transformed(near, m20, 0)});
  return cases;
}

// ---------------------------------------------------------------------------------------------
// Output.

std::string shortest(double x) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  std::string s(buf, r.ptr);
  if (std::strtod(s.c_str(), nullptr) != x) throw std::logic_error("no round trip for " + s);
  if (s == "-0") s = "0";
  return s;
}

std::string coordinate(double x, bool decimal_micro) {
  if (!decimal_micro) return shortest(x);
  if (x != std::floor(x) || std::fabs(x) > 1e6) throw std::logic_error("not a small integer");
  if (x == 0) return "0";
  return std::to_string(static_cast<long long>(x)) + "e-6";
}

const char* to_string(Kind kind) {
  return kind == Kind::crossing ? "crossing" : "touching";
}

std::string answer_text(const std::vector<Pair>& pairs) {
  if (pairs.empty()) return "no intersecting pair";
  std::string s;
  for (const Pair& p : pairs) {
    if (!s.empty()) s += "; ";
    s += std::to_string(p.a) + "-" + std::to_string(p.b) + " " + to_string(p.kind);
  }
  return s;
}

std::string join_ints(const std::vector<int>& ids, const char* sep) {
  std::string s;
  for (int id : ids) s += (s.empty() ? "" : sep) + std::to_string(id);
  return s;
}

std::vector<Variant> variants_of(const Case& c) {
  if (!c.variants.empty()) return c.variants;
  return {{"", "", c.mesh.pairs}};
}

/// Applies the nudges and checks what the answers must satisfy.
Case finished(Case c) {
  for (const Nudge& n : c.mesh.nudges) {
    if (c.decimal_micro) throw std::logic_error(c.name + ": nudge in a decimal case");
    double& x = c.mesh.v.at(n.vertex)[n.axis];
    x = std::nextafter(x, n.direction > 0 ? std::numeric_limits<double>::infinity()
                                          : -std::numeric_limits<double>::infinity());
  }
  c.mesh.nudges.clear();
  if (c.description.find_first_of(",\"\n") != std::string::npos)
    throw std::logic_error(c.name + ": description has a comma, quote or newline");
  const int faces = static_cast<int>(c.mesh.f.size());
  for (const auto& face : c.mesh.f)
    for (int id : face)
      if (id < 0 || id >= static_cast<int>(c.mesh.v.size()))
        throw std::logic_error(c.name + ": vertex id out of range");
  c.variants = variants_of(c);
  for (Variant& variant : c.variants) {
    std::sort(variant.pairs.begin(), variant.pairs.end(),
              [](const Pair& x, const Pair& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    for (size_t i = 0; i < variant.pairs.size(); ++i) {
      const Pair& p = variant.pairs[i];
      if (!(0 <= p.a && p.a < p.b && p.b < faces)) throw std::logic_error(c.name + ": bad pair");
      if (i > 0 && variant.pairs[i - 1].a == p.a && variant.pairs[i - 1].b == p.b)
        throw std::logic_error(c.name + ": repeated pair");
    }
  }
  std::sort(c.mesh.degenerate.begin(), c.mesh.degenerate.end());
  return c;
}

std::string obj_text(const Case& c) {
  std::ostringstream out;
  out << "# snag hard case " << c.name << ": " << c.description << "\n";
  for (const Variant& variant : c.variants) {
    out << "# expected" << (variant.weld.empty() ? "" : " with --weld " + variant.weld)
        << " (faces 0-based in file order): " << answer_text(variant.pairs) << "\n";
  }
  out << "# degenerate (zero-area) faces: "
      << (c.mesh.degenerate.empty() ? "none" : join_ints(c.mesh.degenerate, " ")) << "\n";
  out << "# written by snag-hard-cases (samples/hard_cases.cpp); see samples/hard/README.md\n";
  for (const P3& p : c.mesh.v)
    out << "v " << coordinate(p[0], c.decimal_micro) << ' ' << coordinate(p[1], c.decimal_micro)
        << ' ' << coordinate(p[2], c.decimal_micro) << "\n";
  for (const auto& f : c.mesh.f)
    out << "f " << f[0] + 1 << ' ' << f[1] + 1 << ' ' << f[2] + 1 << "\n";
  return out.str();
}

std::string cases_csv(const std::vector<Case>& cases) {
  std::string s = "case,file,weld,degenerate_faces,description\n";
  for (const Case& c : cases)
    for (const Variant& v : c.variants)
      s += c.name + v.suffix + "," + c.name + ".obj," + v.weld + "," +
           join_ints(c.mesh.degenerate, " ") + "," + c.description + "\n";
  return s;
}

std::string expected_csv(const std::vector<Case>& cases) {
  std::string s = "case,face_a,face_b,kind\n";
  for (const Case& c : cases)
    for (const Variant& v : c.variants)
      for (const Pair& p : v.pairs)
        s += c.name + v.suffix + "," + std::to_string(p.a) + "," + std::to_string(p.b) + "," +
             to_string(p.kind) + "\n";
  return s;
}

std::string readme(const std::vector<Case>& cases) {
  std::ostringstream out;
  out << "# samples/hard: hard cases with exact expected answers\n\n"
      << "Small OBJ meshes of exact contacts (coplanar overlap, a vertex exactly on a face or an\n"
      << "edge, an edge exactly through an edge, shared vertices and edges), the same moved by\n"
      << "one unit in the last place (`std::nextafter` on one coordinate) towards and away from\n"
      << "contact, slivers, zero-area faces, duplicated faces and vertices, and whole meshes\n"
      << "offset by 1e6, 1e9 and 2^30 and scaled by 1e6, 2^-20 and (in decimal) 1e-6.\n\n"
      << "Every answer was derived from the construction (the reasoning is beside each one in\n"
      << "`samples/hard_cases.cpp`), never from snag's output, and cross-checked with CGAL.\n"
      << "`tests/validators/hard_cases_test.cpp` checks, for every case, that snag's pairs,\n"
      << "kinds and degenerate faces equal the files below (`--exact uncertain` and `all`, 1\n"
      << "and 2 threads; `--exact off` whenever it reports no decision outside its filter's\n"
      << "bound), that CGAL's `self_intersections` (and its rules applied pair by pair, for\n"
      << "soups its halfedge mesh cannot hold) finds the same pairs, that CGAL's exact\n"
      << "intersection gives the same kinds and CGAL's exact `collinear` the same zero-area\n"
      << "faces.\n\n"
      << "| file | what |\n|---|---|\n"
      << "| `<case>.obj` | one mesh; its first lines say what it is and the answer |\n"
      << "| `cases.csv` | `case,file,weld,degenerate_faces,description`: every case, with or "
         "without pairs; `weld` is empty (no weld) or the `--weld` tolerance; "
         "`degenerate_faces` lists zero-area faces (space-separated), which snag reports on "
         "their own and leaves out of the pair search |\n"
      << "| `expected.csv` | `case,face_a,face_b,kind`: one row per intersecting pair, face ids "
         "0-based in file order, `face_a < face_b`, kind `crossing` or `touching` |\n\n"
      << "Kinds: `crossing` when the triangles are not coplanar, each has corners strictly on\n"
      << "both sides of the other's plane, and they share a segment of positive length;\n"
      << "`touching` for every other intersecting pair. Faces sharing an edge intersect only\n"
      << "when coplanar and folded onto each other; faces sharing a vertex intersect when they\n"
      << "meet anywhere else. Sharing is by vertex id (after `--weld` where a case has one).\n\n"
      << "The files are written by `snag-hard-cases` (`samples/hard_cases.cpp`, standard\n"
      << "library only), and the test `samples_hard_cases_current` fails when they differ from\n"
      << "what it writes:\n\n"
      << "    cmake --build build --target snag-hard-cases\n"
      << "    build/samples/snag-hard-cases -o samples/hard\n\n"
      << "Try one with the CLI: `snag check samples/hard/edge_through_edge.obj -o /tmp/r`\n"
      << "(`--weld 0` for the `_weld0` rows). The CLI takes a trailing number in a file's name\n"
      << "for its frame number, so `combo_offset_1e6.obj` is reported as frame 6.\n\n"
      << "Coordinates are written in the shortest form that reads back as the same double\n"
      << "(`std::to_chars`), so `1.9999999999999998` is exactly `nextafter(2, 0)`. In\n"
      << "`combo_scale_1em6` they are decimals `Ne-6`, read as the nearest doubles; the\n"
      << "generator's comments argue why each contact survives that rounding.\n\n"
      << "## Cases\n\n"
      << "| case | weld | faces | expected pairs | degenerate | what it is |\n"
      << "|---|---|---|---|---|---|\n";
  for (const Case& c : cases)
    for (const Variant& v : c.variants) {
      std::string what = v.suffix.empty() ? c.description : "as `" + c.name + "`";
      if (c.name.rfind("combo", 0) == 0 && c.name != "combo" && c.name != "combo_near")
        what = c.description;
      if (c.name == "combo")
        what = "the exact contacts of " + std::to_string(combo_parts().size()) +
               " cases above side by side";
      if (c.name == "combo_near")
        what = "the tilted exact contacts and the " + std::to_string(near_cases().size()) +
               " one-ulp cases above side by side; ulps taken after each transform";
      const std::string pairs = c.name.rfind("combo", 0) == 0
                                    ? std::to_string(v.pairs.size()) + " pairs (see expected.csv)"
                                    : answer_text(v.pairs);
      out << "| `" << c.name << v.suffix << "` | " << (v.weld.empty() ? "" : v.weld) << " | "
          << c.mesh.f.size() << " | " << pairs << " | " << join_ints(c.mesh.degenerate, " ")
          << " | " << what << " |\n";
    }
  return out.str();
}

std::map<std::string, std::string> corpus() {
  std::vector<Case> cases;
  std::map<std::string, int> seen;
  for (Case& c : make_cases()) {
    if (seen[c.name]++) throw std::logic_error("two cases named " + c.name);
    cases.push_back(finished(std::move(c)));
  }
  std::map<std::string, std::string> files;
  for (const Case& c : cases) files[c.name + ".obj"] = obj_text(c);
  files["cases.csv"] = cases_csv(cases);
  files["expected.csv"] = expected_csv(cases);
  files["README.md"] = readme(cases);
  return files;
}

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

int usage() {
  std::cerr << "usage: snag-hard-cases -o DIR | --check DIR\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) return usage();
  const std::string_view mode = argv[1];
  const std::filesystem::path dir = argv[2];
  try {
    const auto files = corpus();
    if (mode == "-o" || mode == "--output-dir") {
      std::filesystem::create_directories(dir);
      for (const auto& [name, text] : files) {
        const auto tmp = dir / (name + ".tmp");
        std::ofstream(tmp, std::ios::binary) << text;
        std::filesystem::rename(tmp, dir / name);
      }
      std::cout << "wrote " << files.size() << " files to " << dir.string() << "\n";
      return 0;
    }
    if (mode != "--check") return usage();
    int stale = 0;
    for (const auto& [name, text] : files)
      if (!std::filesystem::exists(dir / name) || read_all(dir / name) != text) {
        std::cerr << "differs from the generator: " << (dir / name).string() << "\n";
        ++stale;
      }
    for (const auto& entry : std::filesystem::directory_iterator(dir))
      if (!files.count(entry.path().filename().string())) {
        std::cerr << "not written by the generator: " << entry.path().string() << "\n";
        ++stale;
      }
    if (stale) {
      std::cerr << stale << " file(s) stale; run: snag-hard-cases -o " << dir.string() << "\n";
      return 1;
    }
    std::cout << files.size() << " files match the generator\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "snag-hard-cases: " << e.what() << "\n";
    return 1;
  }
}
