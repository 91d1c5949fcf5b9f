// The per-topology arrays on the device, uploaded once by set_topology: what the pair tests
// and the expansion of hits into face pairs read. The neighbour list of the CPU backend is not
// among them: the GPU's subwalks list neighbouring triangles with the rest (launch_self_check).
//
// Memory: triangles 12 B, triangle edges 12 B, ownership 2 x 1 B and degenerate flags 1 B per
// triangle; edges 8 B and edge-face offsets 4 B per edge, 4 B per edge-face incidence; fans 4 B
// of offset and 1 B of flag per vertex, 8 B per fan step (about 7 per vertex of a cloth).
#pragma once

#include <array>
#include <cstdint>

#include "device_buffer.cuh"
#include "snag/detect/topology.h"
#include "snag/geom/vec3.h"

namespace snag::cuda {

struct DeviceTopology {
  DeviceBuffer<geom::Tri> triangles;
  DeviceBuffer<std::array<int32_t, 2>> edges;
  DeviceBuffer<std::array<int32_t, 3>> triangle_edges;
  DeviceBuffer<uint8_t> owned_edges;        ///< the topology's ownership
  DeviceBuffer<uint8_t> frame_owned_edges;  ///< a frame's, when it has degenerate triangles
  DeviceBuffer<uint8_t> degenerate;         ///< per triangle: 1 when left out of this frame
  DeviceBuffer<int32_t> edge_face_offsets;
  DeviceBuffer<int32_t> edge_faces;
  DeviceBuffer<int32_t> degenerate_list;  ///< upload area for a frame's degenerate ids
  DeviceBuffer<int32_t> fan_begin;        ///< Topology::fan_begin (empty: no vertex has a fan)
  DeviceBuffer<detect::FanStep> fan_steps;
  DeviceBuffer<uint8_t> fan_clear;  ///< per vertex, this frame: detect::fan_is_clear
  bool has_fans = false;
  int32_t triangle_count = 0;
  int32_t vertex_count = 0;
  int32_t edge_count = 0;
};

}  // namespace snag::cuda
