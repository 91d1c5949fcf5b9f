// The CUDA backend: device buffers per topology and per sequence, one stream, and the frame's
// stages as kernels over the shared per-item functions. Results are produced exactly as the CPU
// backend produces them (lib/src/detect/cpu_backend.cpp): the same sets, sorted the same way.
#include "snag/cuda/cuda_backend.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>

#include "cuda_check.cuh"
#include "detect_kernels.cuh"
#include "device_buffer.cuh"
#include "device_topology.cuh"
#include "device_tree.cuh"
#include "snag/error.h"

namespace snag::cuda {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Bits that hold every value below `count` (at least 1).
int bits_for(int64_t count) {
  int bits = 1;
  while (bits < 62 && (int64_t{1} << bits) < count) ++bits;
  return bits;
}

template <class T>
void upload(DeviceBuffer<T>& buffer, const T* data, size_t count, cudaStream_t stream) {
  buffer.reserve(std::max<size_t>(count, 1));
  if (count)
    SNAG_CUDA_CHECK(cudaMemcpyAsync(buffer.data(), data, count * sizeof(T), cudaMemcpyHostToDevice, stream));
}

/// Makes `device` current before any other member creates a CUDA object.
struct SelectDevice {
  explicit SelectDevice(int device) { SNAG_CUDA_CHECK(cudaSetDevice(device)); }
};

class CudaBackendImpl final : public CudaBackend {
 public:
  explicit CudaBackendImpl(int device) : select_(device), device_(device) {
    cudaDeviceProp prop{};
    SNAG_CUDA_CHECK(cudaGetDeviceProperties(&prop, device));
    device_name_ = prop.name;
    stream_ = std::make_unique<Stream>();
    counters_.reserve(1);
    counters_host_.reserve(1);
    unique_count_.reserve(2);  // [0]: pairs kept by the unique pass, [1]: the expansion's fill
  }

  std::string_view name() const override { return "cuda"; }
  std::string device_name() const override { return device_name_; }
  StageTimes last_times() const override { return times_; }
  void set_result_capacity(int64_t entries) override { initial_capacity_ = std::max<int64_t>(entries, 1); }
  void set_level_by_level_refit(bool on) override { tree_.level_by_level_refit = on; }
  void start_timer() override { span_timer_.start(stream()); }
  double stop_timer() override { return span_timer_.stop(stream()); }

  void set_topology(const detect::Topology& topology) override {
    topology_ = &topology;
    const cudaStream_t s = stream();
    DeviceTopology& d = topo_;
    d.triangle_count = topology.triangle_count();
    d.vertex_count = topology.vertex_count;
    d.edge_count = static_cast<int32_t>(topology.edges.size());
    d.neighbor_pair_count = static_cast<int64_t>(topology.neighbor_pairs.size());
    const size_t n = static_cast<size_t>(d.triangle_count);
    upload(d.triangles, topology.triangles.data(), n, s);
    upload(d.edges, topology.edges.data(), topology.edges.size(), s);
    upload(d.triangle_edges, topology.triangle_edges.data(), n, s);
    upload(d.owned_edges, topology.owned_edges.data(), n, s);
    upload(d.edge_face_offsets, topology.edge_face_offsets.data(), topology.edge_face_offsets.size(), s);
    upload(d.edge_faces, topology.edge_faces.data(), topology.edge_faces.size(), s);
    upload(d.listed_vertex, topology.listed_vertex.data(), topology.listed_vertex.size(), s);
    upload(d.neighbor_pairs, topology.neighbor_pairs.data(), topology.neighbor_pairs.size(), s);
    d.frame_owned_edges.reserve(std::max<size_t>(n, 1));
    d.degenerate.reserve(std::max<size_t>(n, 1));
    d.degenerate_list.reserve(std::max<size_t>(n, 1));
    if (n) SNAG_CUDA_CHECK(cudaMemsetAsync(d.degenerate.data(), 0, n, s));
    flagged_.clear();
    scan_degenerate_.reserve(std::max<size_t>(n, 1));
    scan_uncertain_.reserve(std::max<size_t>(n, 1));
    planes_.reserve(std::max<size_t>(n, 1));
    positions_.reserve(std::max<int32_t>(d.vertex_count, 1));
    positions_host_.reserve(std::max<int32_t>(d.vertex_count, 1));
    current_positions_ = positions_.data();
    pair_bits_ = bits_for(d.triangle_count);
    edge_bits_ = bits_for(d.edge_count);
    tree_.resize(d.triangle_count);
    ensure_result_capacity(initial_capacity_, initial_capacity_, initial_capacity_);
    stream_->synchronize();
  }

  void set_positions(std::span<const geom::Vec3d> positions) override {
    require_topology();
    if (static_cast<int64_t>(positions.size()) != topo_.vertex_count)
      throw InternalError("cuda backend: " + std::to_string(positions.size()) + " positions for " +
                          std::to_string(topo_.vertex_count) + " vertices");
    // The previous upload from the pinned buffer finished: every stage ends with a sync.
    std::memcpy(positions_host_.data(), positions.data(), positions.size_bytes());
    timer_.start(stream());
    SNAG_CUDA_CHECK(cudaMemcpyAsync(positions_.data(), positions_host_.data(), positions.size_bytes(),
                                    cudaMemcpyHostToDevice, stream()));
    times_.upload = timer_.stop(stream());
    current_positions_ = positions_.data();
  }

  void upload_resident_frames(std::span<const std::span<const geom::Vec3d>> frames) override {
    require_topology();
    const size_t v = static_cast<size_t>(topo_.vertex_count);
    resident_.reserve(std::max<size_t>(frames.size() * v, 1));
    for (size_t f = 0; f < frames.size(); ++f) {
      if (frames[f].size() != v) throw InternalError("cuda backend: a resident frame has the wrong vertex count");
      SNAG_CUDA_CHECK(cudaMemcpy(resident_.data() + f * v, frames[f].data(), v * sizeof(geom::Vec3d),
                                 cudaMemcpyHostToDevice));
    }
    resident_count_ = static_cast<int>(frames.size());
  }

  void select_resident_frame(int index) override {
    if (index < 0 || index >= resident_count_) throw InternalError("cuda backend: no resident frame " + std::to_string(index));
    current_positions_ = resident_.data() + static_cast<size_t>(index) * static_cast<size_t>(topo_.vertex_count);
  }

  detect::DegeneracyScan scan_degenerate() override {
    require_topology();
    const int32_t n = topo_.triangle_count;
    detect::DegeneracyScan scan;
    if (n == 0) return scan;
    const cudaStream_t s = stream();
    timer_.start(s);
    SNAG_CUDA_CHECK(cudaMemsetAsync(counters_.data(), 0, sizeof(FrameCounters), s));
    launch_scan_degenerate(current_positions_, topo_.triangles.data(), n, scan_degenerate_.data(),
                           scan_uncertain_.data(), counters_.data(), s);
    const FrameCounters c = read_counters();
    scan.degenerate.resize(c.degenerate);
    scan.uncertain.resize(c.degenerate_uncertain);
    if (c.degenerate)
      SNAG_CUDA_CHECK(cudaMemcpyAsync(scan.degenerate.data(), scan_degenerate_.data(), c.degenerate * sizeof(int32_t),
                                      cudaMemcpyDeviceToHost, s));
    if (c.degenerate_uncertain)
      SNAG_CUDA_CHECK(cudaMemcpyAsync(scan.uncertain.data(), scan_uncertain_.data(),
                                      c.degenerate_uncertain * sizeof(int32_t), cudaMemcpyDeviceToHost, s));
    times_.scan = timer_.stop(s);
    // Appended in any order: sorted as the CPU gives them.
    std::sort(scan.degenerate.begin(), scan.degenerate.end());
    std::sort(scan.uncertain.begin(), scan.uncertain.end());
    return scan;
  }

  void build() override {
    require_topology();
    timer_.start(stream());
    tree_.build(mesh_view(), stream());
    times_.build = timer_.stop(stream());
  }

  void refit() override {
    require_topology();
    timer_.start(stream());
    tree_.refit(mesh_view(), stream());
    times_.refit = timer_.stop(stream());
  }

  double tree_quality() override {
    require_topology();
    timer_.start(stream());
    const double q = tree_.quality(stream());
    times_.quality = timer_.stop(stream());
    return q;
  }

  std::vector<int32_t> triangle_order() override {
    std::vector<int32_t> order(static_cast<size_t>(tree_.shape().leaf_count));
    if (!order.empty())
      SNAG_CUDA_CHECK(cudaMemcpy(order.data(), tree_.view().triangle_at, order.size() * sizeof(int32_t),
                                 cudaMemcpyDeviceToHost));
    return order;
  }

  std::vector<geom::Box3f> node_boxes() override {
    const int32_t n = tree_.shape().leaf_count;
    std::vector<geom::Box3f> boxes(n > 0 ? static_cast<size_t>(2 * n - 1) : 0);
    if (!boxes.empty())
      SNAG_CUDA_CHECK(cudaMemcpy(boxes.data(), tree_.view().boxes, boxes.size() * sizeof(geom::Box3f),
                                 cudaMemcpyDeviceToHost));
    return boxes;
  }

  detect::FilteredFrame detect(std::span<const int32_t> degenerate) override;

 private:
  cudaStream_t stream() const { return stream_->get(); }

  void require_topology() const {
    if (!topology_) throw InternalError("cuda backend: no topology set");
  }

  mesh::MeshView mesh_view() const {
    return {current_positions_, topo_.triangles.data(), topo_.vertex_count, topo_.triangle_count};
  }

  FrameCounters read_counters() {
    SNAG_CUDA_CHECK(cudaMemcpyAsync(counters_host_.data(), counters_.data(), sizeof(FrameCounters),
                                    cudaMemcpyDeviceToHost, stream()));
    stream_->synchronize();
    return *counters_host_.data();
  }

  void ensure_result_capacity(uint64_t hits, uint64_t uncertain, uint64_t duplicates) {
    hits_.reserve(hits);
    uncertain_.reserve(uncertain);
    duplicates_.reserve(duplicates);
  }

  /// The frame's degenerate flags and edge ownership on the device.
  const uint8_t* prepare_degenerate(std::span<const int32_t> degenerate);

  SelectDevice select_;
  int device_;
  std::string device_name_;
  std::unique_ptr<Stream> stream_;
  EventTimer timer_, span_timer_;
  StageTimes times_;
  const detect::Topology* topology_ = nullptr;
  DeviceTopology topo_;
  DeviceTree tree_;
  DeviceBuffer<geom::Vec3d> positions_, resident_;
  PinnedBuffer<geom::Vec3d> positions_host_;
  const geom::Vec3d* current_positions_ = nullptr;
  int resident_count_ = 0;
  DeviceBuffer<geom::PlaneCoefficients> planes_;
  DeviceBuffer<int32_t> scan_degenerate_, scan_uncertain_;
  std::vector<int32_t> flagged_;  ///< degenerate ids flagged on the device for the last frame
  DeviceBuffer<FrameCounters> counters_;
  PinnedBuffer<FrameCounters> counters_host_;
  DeviceBuffer<uint64_t> hits_, uncertain_, duplicates_;
  DeviceBuffer<uint64_t> keys_, keys_alt_, unique_keys_;
  DeviceBuffer<uint8_t> status_;
  DeviceBuffer<unsigned long long> unique_count_;
  DeviceBuffer<unsigned char> temp_;
  PinnedBuffer<uint64_t> keys_host_, uncertain_host_;
  PinnedBuffer<uint8_t> status_host_;
  PinnedBuffer<unsigned long long> unique_count_host_;
  int64_t initial_capacity_ = 1 << 16;
  int pair_bits_ = 1, edge_bits_ = 1;
};

const uint8_t* CudaBackendImpl::prepare_degenerate(std::span<const int32_t> degenerate) {
  const cudaStream_t s = stream();
  const size_t n = static_cast<size_t>(topo_.triangle_count);
  const bool same = flagged_.size() == degenerate.size() && std::equal(flagged_.begin(), flagged_.end(), degenerate.begin());
  if (!same) {
    if (!flagged_.empty()) SNAG_CUDA_CHECK(cudaMemsetAsync(topo_.degenerate.data(), 0, n, s));
    if (!degenerate.empty()) {
      SNAG_CUDA_CHECK(cudaMemcpyAsync(topo_.degenerate_list.data(), degenerate.data(), degenerate.size_bytes(),
                                      cudaMemcpyHostToDevice, s));
      launch_flag_degenerate(topo_.degenerate_list.data(), static_cast<int32_t>(degenerate.size()),
                             topo_.degenerate.data(), s);
      // Degenerate triangles own nothing this frame: their edges go to the next incident face.
      const std::vector<uint8_t> owned = detect::ownership_without(*topology_, degenerate);
      SNAG_CUDA_CHECK(cudaMemcpyAsync(topo_.frame_owned_edges.data(), owned.data(), n, cudaMemcpyHostToDevice, s));
      stream_->synchronize();  // `owned` is a local: the copy must finish before it goes
    }
    flagged_.assign(degenerate.begin(), degenerate.end());
  }
  return flagged_.empty() ? topo_.owned_edges.data() : topo_.frame_owned_edges.data();
}

detect::FilteredFrame CudaBackendImpl::detect(std::span<const int32_t> degenerate) {
  require_topology();
  detect::FilteredFrame frame;
  const int32_t n = topo_.triangle_count;
  if (n == 0) return frame;
  const cudaStream_t s = stream();
  const auto start = Clock::now();
  timer_.start(s);

  const uint8_t* owned = prepare_degenerate(degenerate);
  launch_planes(current_positions_, topo_.triangles.data(), n, planes_.data(), s);
  PairInputs inputs;
  inputs.frame = {current_positions_, planes_.data()};
  inputs.topology.triangles = topo_.triangles.data();
  inputs.topology.edges = topo_.edges.data();
  inputs.topology.triangle_edges = topo_.triangle_edges.data();
  inputs.topology.owned_edges = owned;
  inputs.topology.listed_vertex = topo_.listed_vertex.data();
  inputs.topology.every_vertex_listed = topology_->every_vertex_listed;
  inputs.topology.triangle_count = n;
  inputs.topology.edge_count = topo_.edge_count;
  inputs.degenerate = topo_.degenerate.data();

  // Traverse; when a buffer overflowed, grow it to what was found and traverse again.
  FrameCounters c{};
  for (;;) {
    ResultBuffers results;
    results.hits = hits_.data();
    results.uncertain = uncertain_.data();
    results.duplicates = duplicates_.data();
    results.hit_capacity = hits_.capacity();
    results.uncertain_capacity = uncertain_.capacity();
    results.duplicate_capacity = duplicates_.capacity();
    results.counters = counters_.data();
    results.edge_face_offsets = topo_.edge_face_offsets.data();
    SNAG_CUDA_CHECK(cudaMemsetAsync(counters_.data(), 0, sizeof(FrameCounters), s));
    launch_narrow_phase(tree_.view(), inputs, topo_.neighbor_pairs.data(), topo_.neighbor_pair_count, results, s);
    c = read_counters();
    if (c.hits <= hits_.capacity() && c.uncertain <= uncertain_.capacity() && c.duplicates <= duplicates_.capacity())
      break;
    ensure_result_capacity(c.hits, c.uncertain, c.duplicates);
  }
  times_.traverse = timer_.stop(s);
  frame.traverse_seconds = seconds_since(start);
  frame.candidate_pairs = static_cast<int64_t>(c.candidates);

  const auto classify_start = Clock::now();
  timer_.start(s);
  const unsigned long long slots = c.expanded + c.duplicates;
  const uint64_t sentinel = ~uint64_t{0};
  const int key_bits = 2 * pair_bits_;
  const int task_bits = 32 + edge_bits_;
  // Every buffer and the scratch are sized before anything is queued: nothing queued may see
  // a buffer reallocated under it.
  {
    const size_t alt = std::max<size_t>(std::max<size_t>(slots, c.uncertain), 1);
    keys_.reserve(std::max<size_t>(slots, 1));
    keys_alt_.reserve(alt);
    unique_keys_.reserve(std::max<size_t>(slots, 1));
    status_.reserve(std::max<size_t>(slots, 1));
    keys_host_.reserve(std::max<size_t>(slots, 1));
    status_host_.reserve(std::max<size_t>(slots, 1));
    uncertain_host_.reserve(std::max<size_t>(c.uncertain, 1));
    unique_count_host_.reserve(1);
    size_t need = 0, bytes = 0;
    cub::DoubleBuffer<uint64_t> pairs(keys_.data(), keys_alt_.data()), tasks(uncertain_.data(), keys_alt_.data());
    if (slots) {
      SNAG_CUDA_CHECK(cub::DeviceRadixSort::SortKeys(nullptr, bytes, pairs, static_cast<int64_t>(slots), 0, key_bits, s));
      need = std::max(need, bytes);
      SNAG_CUDA_CHECK(cub::DeviceSelect::Unique(nullptr, bytes, keys_.data(), unique_keys_.data(), unique_count_.data(),
                                                static_cast<int64_t>(slots), s));
      need = std::max(need, bytes);
    }
    if (c.uncertain) {
      SNAG_CUDA_CHECK(cub::DeviceRadixSort::SortKeys(nullptr, bytes, tasks, static_cast<int64_t>(c.uncertain), 0,
                                                     task_bits, s));
      need = std::max(need, bytes);
    }
    temp_.reserve(std::max<size_t>(need, 1));
  }
  if (slots) {
    // Pairs: expand the hits, add the duplicated faces, sort, unique, classify. Slots the
    // expansion leaves empty keep the sentinel, which sorts last.
    SNAG_CUDA_CHECK(cudaMemsetAsync(keys_.data(), 0xff, slots * sizeof(uint64_t), s));
    SNAG_CUDA_CHECK(cudaMemsetAsync(unique_count_.data(), 0, 2 * sizeof(unsigned long long), s));
    launch_expand(hits_.data(), c.hits, duplicates_.data(), c.duplicates, topo_.edge_face_offsets.data(),
                  topo_.edge_faces.data(), topo_.degenerate.data(), pair_bits_, keys_.data(), unique_count_.data() + 1, s);
    cub::DoubleBuffer<uint64_t> sorted(keys_.data(), keys_alt_.data());
    size_t bytes = temp_.capacity();
    SNAG_CUDA_CHECK(cub::DeviceRadixSort::SortKeys(temp_.data(), bytes, sorted, static_cast<int64_t>(slots), 0,
                                                   key_bits, s));
    bytes = temp_.capacity();
    SNAG_CUDA_CHECK(cub::DeviceSelect::Unique(temp_.data(), bytes, sorted.Current(), unique_keys_.data(),
                                              unique_count_.data(), static_cast<int64_t>(slots), s));
    launch_classify(unique_keys_.data(), unique_count_.data(), slots, pair_bits_, sentinel, current_positions_,
                    topo_.triangles.data(), status_.data(), s);
    SNAG_CUDA_CHECK(cudaMemcpyAsync(unique_count_host_.data(), unique_count_.data(), sizeof(unsigned long long),
                                    cudaMemcpyDeviceToHost, s));
    SNAG_CUDA_CHECK(cudaMemcpyAsync(keys_host_.data(), unique_keys_.data(), slots * sizeof(uint64_t),
                                    cudaMemcpyDeviceToHost, s));
    SNAG_CUDA_CHECK(cudaMemcpyAsync(status_host_.data(), status_.data(), slots, cudaMemcpyDeviceToHost, s));
  }
  if (c.uncertain) {
    // Uncertain tests sorted by (edge, triangle), the keys' order; the alternate buffer is free
    // again once the pair sort before it (same stream) is done.
    cub::DoubleBuffer<uint64_t> sorted(uncertain_.data(), keys_alt_.data());
    size_t bytes = temp_.capacity();
    SNAG_CUDA_CHECK(cub::DeviceRadixSort::SortKeys(temp_.data(), bytes, sorted, static_cast<int64_t>(c.uncertain), 0,
                                                   task_bits, s));
    SNAG_CUDA_CHECK(cudaMemcpyAsync(uncertain_host_.data(), sorted.Current(), c.uncertain * sizeof(uint64_t),
                                    cudaMemcpyDeviceToHost, s));
  }
  stream_->synchronize();

  int64_t uncertain_kinds = 0;
  if (slots) {
    unsigned long long count = *unique_count_host_.data();
    if (count && keys_host_.data()[count - 1] == sentinel) --count;
    frame.pairs.resize(count);
    frame.kind_certain.resize(count);
    const uint64_t mask = (uint64_t{1} << pair_bits_) - 1;
    for (unsigned long long i = 0; i < count; ++i) {
      const uint64_t key = keys_host_.data()[i];
      const uint8_t status = status_host_.data()[i];
      frame.pairs[i] = {static_cast<int32_t>(key >> pair_bits_), static_cast<int32_t>(key & mask),
                        static_cast<detect::PairKind>(status & 1)};
      frame.kind_certain[i] = static_cast<uint8_t>(status >> 1);
      uncertain_kinds += 1 - (status >> 1);
    }
  }
  frame.uncertain.resize(c.uncertain);
  for (unsigned long long i = 0; i < c.uncertain; ++i) {
    const uint64_t key = uncertain_host_.data()[i];
    frame.uncertain[i] = {static_cast<int32_t>(key >> 32), static_cast<int32_t>(key & 0xffffffffu)};
  }
  frame.filtered_tests = static_cast<int64_t>(c.misses + c.hits) + static_cast<int64_t>(frame.pairs.size()) - uncertain_kinds;
  times_.classify = timer_.stop(s);
  frame.classify_seconds = seconds_since(classify_start);
  return frame;
}

}  // namespace

int cuda_device_count() {
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) {
    cudaGetLastError();  // no driver or no device: not an error here, and not left pending
    return 0;
  }
  return count;
}

std::unique_ptr<detect::Backend> make_cuda_backend(int device) {
  const int count = cuda_device_count();
  if (count == 0) throw InternalError("no CUDA device is usable here (no GPU, or no driver)");
  if (device < 0 || device >= count)
    throw InternalError("--device " + std::to_string(device) + ": there are " + std::to_string(count) +
                     " CUDA device(s), numbered from 0");
  return std::make_unique<CudaBackendImpl>(device);
}

}  // namespace snag::cuda
