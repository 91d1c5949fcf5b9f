// The CUDA backend: device buffers per topology and per sequence, one stream, and the frame's
// stages as kernels over the shared per-item functions. Results are produced exactly as the CPU
// backend produces them (lib/src/detect/cpu_backend.cpp): the same sets, sorted the same way.
#include "snag/cuda/cuda_backend.h"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <cub/device/device_radix_sort.cuh>
#include <utility>

#include "cuda_check.cuh"
#include "detect_kernels.cuh"
#include "device_buffer.cuh"
#include "device_topology.cuh"
#include "device_tree.cuh"
#include "host_staging.cuh"
#include "snag/error.h"
#include "trace.cuh"

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
    SNAG_CUDA_CHECK(
        cudaMemcpyAsync(buffer.data(), data, count * sizeof(T), cudaMemcpyHostToDevice, stream));
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
    // Kernels whose item count is known only on the device stride over it with this many blocks
    // at most: about one full wave of 256-thread blocks.
    max_blocks_ = static_cast<unsigned>(std::max(prop.multiProcessorCount, 1)) * 8u;
    stream_ = std::make_unique<Stream>();
    upload_stream_ = std::make_unique<Stream>();
    side_stream_ = std::make_unique<Stream>();
    counters_.reserve(1);
    for (auto& counters : counters_host_) counters.reserve(1);
    scan_counters_.reserve(1);
    scan_counts_host_.reserve(1);
    SNAG_CUDA_CHECK(
        cudaMemsetAsync(scan_counters_.data(), 0, sizeof(ScanCounters), side_stream_->get()));
    finish_ranks_.reserve(2 * kFinishLimit);
    finish_tickets_.reserve(2 * kFinishSlices);
    SNAG_CUDA_CHECK(
        cudaMemsetAsync(finish_ranks_.data(), 0, 2 * kFinishLimit * sizeof(unsigned), stream()));
    SNAG_CUDA_CHECK(
        cudaMemsetAsync(finish_tickets_.data(), 0, 2 * kFinishSlices * sizeof(unsigned), stream()));
  }

  ~CudaBackendImpl() override {
    // A staged copy may still be reading a pinned buffer that is about to be freed.
    if (upload_stream_) cudaStreamSynchronize(upload_stream_->get());
    // A frame cut short by an exception may still be writing pinned buffers: its scan, or the
    // detect queued ahead of it.
    if (side_stream_) cudaStreamSynchronize(side_stream_->get());
    if (stream_) cudaStreamSynchronize(stream_->get());
  }

  std::string_view name() const override { return "cuda"; }
  std::string device_name() const override { return device_name_; }
  AheadTaken ahead_taken() const override { return ahead_taken_; }

  std::vector<TracedLaunch> take_stream_trace() override {
    std::vector<TracedLaunch> launches;
    TraceRecord* const buffer = stream_trace_buffer();  // made on first use
    if (buffer == nullptr) return launches;
    SNAG_CUDA_CHECK(cudaDeviceSynchronize());  // every launch queued so far has recorded
    std::vector<TraceRecord> records(kTraceSlots);
    SNAG_CUDA_CHECK(cudaMemcpy(records.data(), buffer, kTraceSlots * sizeof(TraceRecord),
                               cudaMemcpyDeviceToHost));
    reset_stream_trace(buffer);
    std::erase_if(records, [](const TraceRecord& r) { return r.grid == 0; });
    std::ranges::sort(records, {}, &TraceRecord::began);
    const unsigned long long origin = records.empty() ? 0 : records.front().began;
    const auto us = [&](unsigned long long ns) { return static_cast<double>(ns - origin) * 1e-3; };
    for (const TraceRecord& r : records)
      launches.push_back(
          {static_cast<int64_t>(r.threads), us(r.began), us(r.passed_first), us(r.passed_last)});
    return launches;
  }
  StageTimes last_times() const override {
    collect_times();  // waits for stages still queued
    return times_;
  }
  void set_result_capacity(int64_t entries) override {
    initial_capacity_ = std::max<int64_t>(entries, 1);
    finish_limit_ = std::min<unsigned long long>(
        kFinishLimit, static_cast<unsigned long long>(initial_capacity_));
  }
  void set_level_by_level_refit(bool on) override {
    level_by_level_refit_ = on;
    for (auto& tree : trees_) tree->level_by_level_refit = on;
  }
  void start_timer() override { span_timer_.start(stream()); }
  double stop_timer() override { return span_timer_.stop(stream()); }

  void set_topology(const detect::Topology& topology) override {
    // Work queued ahead, or cut short by an exception, may still use buffers reallocated below.
    stream_->synchronize();
    side_stream_->synchronize();
    drop_staged_positions();
    speculation_ = {};
    ahead_ = {};
    scanned_ = false;
    release_recorded_ = false;
    last_detect_ = {};
    topology_ = &topology;
    const cudaStream_t s = stream();
    DeviceTopology& d = topo_;
    d.triangle_count = topology.triangle_count();
    d.vertex_count = topology.vertex_count;
    d.edge_count = static_cast<int32_t>(topology.edges.size());
    const size_t n = static_cast<size_t>(d.triangle_count);
    upload(d.triangles, topology.triangles.data(), n, s);
    upload(d.edges, topology.edges.data(), topology.edges.size(), s);
    upload(d.triangle_edges, topology.triangle_edges.data(), n, s);
    upload(d.owned_edges, topology.owned_edges.data(), n, s);
    upload(d.edge_face_offsets, topology.edge_face_offsets.data(),
           topology.edge_face_offsets.size(), s);
    upload(d.edge_faces, topology.edge_faces.data(), topology.edge_faces.size(), s);
    d.has_fans = !topology.fan_steps.empty();
    upload(d.fan_begin, topology.fan_begin.data(), d.has_fans ? topology.fan_begin.size() : 0, s);
    upload(d.fan_steps, topology.fan_steps.data(), topology.fan_steps.size(), s);
    d.fan_clear.reserve(std::max<size_t>(d.has_fans ? d.vertex_count : 0, 1));
    later_neighbors_.reserve(std::max<size_t>(d.has_fans ? n : 0, 1));
    leaf_position_.reserve(std::max<size_t>(d.has_fans ? n : 0, 1));
    d.frame_owned_edges.reserve(std::max<size_t>(n, 1));
    d.degenerate.reserve(std::max<size_t>(n, 1));
    d.degenerate_list.reserve(std::max<size_t>(n, 1));
    if (n) SNAG_CUDA_CHECK(cudaMemsetAsync(d.degenerate.data(), 0, n, s));
    flagged_.clear();
    scan_degenerate_host_.reserve(std::max<size_t>(n, 1));
    scan_uncertain_host_.reserve(std::max<size_t>(n, 1));
    for (int set = 0; set < 2; ++set) {
      host_pairs_[set].reserve(kFinishLimit);
      host_uncertain_[set].reserve(kFinishLimit);
      host_results_[set] = {mapped(host_pairs_[set].data()), mapped(host_uncertain_[set].data()),
                            mapped(counters_host_[set].data())};
    }
    planes_.reserve(std::max<size_t>(n, 1));
    for (int slot = 0; slot < 2; ++slot) {
      positions_[slot].reserve(std::max<int32_t>(d.vertex_count, 1));
      positions_host_[slot].reserve(std::max<int32_t>(d.vertex_count, 1));
    }
    current_positions_ = positions_[positions_slot_].data();
    // At most 31 (triangle ids are int32): pair keys leave HostResults' status bits free.
    static_assert(2 * 31 <= kStatusShift);
    pair_bits_ = bits_for(d.triangle_count);
    edge_bits_ = bits_for(d.edge_count);
    // One tree per part, and what each part's device data fits (PartState).
    const int32_t parts = topology.part_count();
    trees_.resize(static_cast<size_t>(parts));
    for (int32_t p = 0; p < parts; ++p) {
      if (!trees_[p]) trees_[p] = std::make_unique<DeviceTree>();
      trees_[p]->level_by_level_refit = level_by_level_refit_;
      trees_[p]->resize(part_size(p), stream());
    }
    part_.assign(static_cast<size_t>(parts), PartState{});
    for (int slot = 0; slot < 2; ++slot) slot_version_[slot].assign(static_cast<size_t>(parts), 0);
    while (check_timers_.size() < topology.checks.size())
      check_timers_.push_back(std::make_unique<EventTimer>());
    ensure_result_capacity(initial_capacity_, initial_capacity_, initial_capacity_,
                           initial_capacity_, initial_capacity_, initial_capacity_);
    subwalks_expected_ = screened_expected_ = expand_expected_ =
        static_cast<uint64_t>(initial_capacity_);
    finish_expected_ = kFinishLimit;
    stream_->synchronize();
  }

  /// Only the parts whose slot holds another version cross the bus: a part that did not move
  /// is copied into each of the two slots once, then never again. When the current slot holds
  /// every part's version already (nothing moved), it stays current and nothing is copied.
  void set_part_positions(std::span<const geom::Vec3d> positions,
                          std::span<const uint8_t> moved) override {
    require_topology();
    if (static_cast<int64_t>(positions.size()) != topo_.vertex_count)
      throw InternalError("cuda backend: " + std::to_string(positions.size()) + " positions for " +
                          std::to_string(topo_.vertex_count) + " vertices");
    moved = moved_per_part(moved);
    const int slot = 1 - positions_slot_;
    scanned_ = false;
    if (staged_ && positions.data() == staged_data_ && positions.size() == staged_size_ &&
        same_moved(moved, staged_moved_)) {
      // Copied across while the previous frame was checked: the stream only waits for the copy
      // (made now if it is still to make: `positions` is that span, valid in this call).
      copy_staged_positions();
      staged_ = false;
      staged_ready_.wait_on(stream());
      upload_pending_ = false;
      times_.upload = 0;
      for (size_t p = 0; p < part_.size(); ++p) part_[p].version = staged_version_[p];
      positions_slot_ = slot;
    } else {
      drop_staged_positions();
      release_recorded_ = false;  // it was for the slot the staged frame would have left
      order_after_ahead();        // a scan queued ahead may still read the slot copied into
      const std::vector<uint64_t> versions = next_versions(moved);
      for (size_t p = 0; p < part_.size(); ++p) part_[p].version = versions[p];
      if (!on_resident_ && slot_version_[positions_slot_] == versions) {
        times_.upload = 0;  // the current slot holds this frame already
      } else {
        // The pinned buffer is free once its last copy is done (long ago in a checker's frame).
        pinned_copied_[slot].synchronize();
        upload_timer_.start(stream());
        copy_stale_parts(positions, slot, versions, stream());
        upload_timer_.stop_async(stream());
        pinned_copied_[slot].record(stream());
        upload_pending_ = true;
        positions_slot_ = slot;
      }
    }
    on_resident_ = false;
    current_positions_ = positions_[positions_slot_].data();
  }

  /// The next frame's positions go into the slot the current frame does not use, on their own
  /// stream, alongside the current frame's kernels. That slot held the previous frame, whose
  /// work is all queued before this point on the main stream: the transfer waits for it (for
  /// the point where it ended, when the current frame's work was queued ahead after it). The
  /// host's copy into pinned memory (40-80 us for 36K triangles; none for positions staged in
  /// pinned memory already, host_staging) and the transfer wait until the current frame's work
  /// is queued (copy_staged_positions, from the scan's wait, else from detect's or the next
  /// set): done here, a checker's frame began with it while the device had nothing to do. Parts
  /// whose version that slot holds already are not copied.
  void stage_part_positions(std::span<const geom::Vec3d> next,
                            std::span<const uint8_t> moved) override {
    if (next.empty()) {  // forget a staged frame: its span may hold another one by now
      drop_staged_positions();
      return;
    }
    require_topology();
    if (static_cast<int64_t>(next.size()) != topo_.vertex_count) return;  // not a next frame
    moved = moved_per_part(moved);
    drop_staged_positions();
    const std::vector<uint64_t> versions = next_versions(moved);
    if (slot_version_[positions_slot_] == versions) return;  // the next frame is this one
    const int slot = 1 - positions_slot_;
    pinned_copied_[slot].synchronize();
    if (!release_recorded_ || slot != released_slot_) {
      order_after_ahead();  // a scan queued ahead may still read the slot copied into
      slot_released_.record(stream());
    }
    release_recorded_ = false;
    slot_released_.wait_on(upload_stream_->get());
    staged_ = true;
    staged_copy_pending_ = true;
    staged_data_ = next.data();
    staged_size_ = next.size();
    staged_moved_.assign(moved.begin(), moved.end());
    staged_version_ = versions;
  }

  std::shared_ptr<detect::HostStaging> host_staging(int buffers) override {
    if (!staging_) staging_ = std::make_shared<PinnedStaging>(device_, buffers);
    return staging_;
  }

  void upload_resident_frames(std::span<const std::span<const geom::Vec3d>> frames) override {
    require_topology();
    const size_t v = static_cast<size_t>(topo_.vertex_count);
    resident_.reserve(std::max<size_t>(frames.size() * v, 1));
    for (size_t f = 0; f < frames.size(); ++f) {
      if (frames[f].size() != v)
        throw InternalError("cuda backend: a resident frame has the wrong vertex count");
      SNAG_CUDA_CHECK(cudaMemcpy(resident_.data() + f * v, frames[f].data(),
                                 v * sizeof(geom::Vec3d), cudaMemcpyHostToDevice));
    }
    resident_count_ = static_cast<int>(frames.size());
  }

  void select_resident_frame(int index) override {
    if (index < 0 || index >= resident_count_)
      throw InternalError("cuda backend: no resident frame " + std::to_string(index));
    current_positions_ =
        resident_.data() + static_cast<size_t>(index) * static_cast<size_t>(topo_.vertex_count);
    for (PartState& part : part_) part.version = ++versions_issued_;
    on_resident_ = true;
    release_recorded_ = false;
  }

  /// The scan of `parts`, and ahead of the refit_part() and part_quality() calls that follow it
  /// in a checker's frame: the refit and the quality of every built tree that does not fit the
  /// current positions, queued before the scan's one wait (refit_part() and part_quality() then
  /// find them done). A build in between makes them moot, not wrong. All of it, and the detect,
  /// may have been queued already at the end of the previous frame's detect (queue_ahead); then
  /// the scan only waits.
  detect::DegeneracyScan scan_degenerate_parts(std::span<const int32_t> parts) override {
    require_topology();
    detect::DegeneracyScan scan;
    if (topo_.triangle_count == 0) return scan;
    scanned_ = true;
    const FrameView view = current_view();
    const bool queued_ahead = ahead_.queued && ahead_.view == view &&
                              ahead_.tree_changes == tree_changes_ &&
                              std::ranges::equal(ahead_.parts, parts);
    // Work queued ahead for another frame than this one still writes the scan's buffers.
    if (ahead_.queued && !queued_ahead) side_stream_->synchronize();
    ahead_.queued = false;
    ahead_taken_.scans += queued_ahead;
    const std::vector<int32_t> refit =
        queued_ahead ? std::move(ahead_.refit) : queue_frame(parts, view, timer_);
    EventTimer& timer = queued_ahead ? ahead_timer_ : timer_;
    copy_staged_positions();        // the next frame's, while the device works on this one
    times_.scan = timer.elapsed();  // the wait: scan, refits and qualities done
    collect_times();
    for (int32_t p : refit) {
      part_[p].quality = trees_[p]->queued_quality();
      part_[p].quality_ready = true;
    }
    const ScanCounts c = *scan_counts_host_.data();
    int64_t scanned = 0;
    for (int32_t p : parts) scanned += part_size(p);
    if (c.degenerate + c.uncertain > static_cast<unsigned long long>(scanned)) {
      // Counters not zero at the start: this scan is lost, and scan_pending_, left set, has
      // the next one clear them first.
      throw InternalError("cuda backend: the degenerate-triangle scan counted " +
                          std::to_string(c.degenerate + c.uncertain) + " of " +
                          std::to_string(scanned) + " triangles");
    }
    scan_pending_ = false;
    scan.degenerate.assign(scan_degenerate_host_.data(),
                           scan_degenerate_host_.data() + c.degenerate);
    scan.uncertain.assign(scan_uncertain_host_.data(), scan_uncertain_host_.data() + c.uncertain);
    // Appended in any order: sorted as the CPU gives them.
    std::sort(scan.degenerate.begin(), scan.degenerate.end());
    std::sort(scan.uncertain.begin(), scan.uncertain.end());
    return scan;
  }

  void build_part(int32_t p) override {
    require_topology();
    PartState& part = part_[p];
    ++tree_changes_;  // a detect queued ahead read the tree this replaces
    part.tree_built = true;
    part.tree_version = part.version;
    part.planes_version = part.version;
    part.quality_ready = false;
    if (part_size(p) == 0) {
      part.quality = 0;
      part.quality_ready = true;
      return;
    }
    order_after_ahead();
    note_reads(current_positions_);
    build_timer_.start(stream());
    trees_[p]->build(part_mesh(p, current_positions_), planes_.data() + part_begin(p), stream());
    if (topo_.has_fans)
      launch_later_neighbors(trees_[p]->view(), part_begin(p), topo_.triangles.data(),
                             {topo_.fan_begin.data(), topo_.fan_steps.data()},
                             leaf_position_.data() + part_begin(p), later_neighbors_.data(),
                             stream());
    build_timer_.stop_async(stream());
    build_pending_ = true;
  }

  /// Skipped when the tree already fits the current positions (refit ahead in the scan, or a
  /// build): times().refit is then 0, its time being in the scan's.
  void refit_part(int32_t p) override {
    require_topology();
    if (part_[p].tree_built && part_[p].tree_version == part_[p].version) {
      times_.refit = 0;
      return;
    }
    queue_refit(p, /*timed=*/true, current_view());
  }

  double part_quality(int32_t p) override {
    require_topology();
    PartState& part = part_[p];
    // A tree refit ahead to the staged frame (queue_ahead) is refit back to this one first.
    if (const FrameView view = current_view(); needs_refit(p, view))
      queue_refit(p, /*timed=*/true, view);
    if (part.quality_ready) return part.quality;
    order_after_ahead();
    timer_.start(stream());
    trees_[p]->queue_quality(stream());
    timer_.stop_async(stream());
    times_.quality = timer_.elapsed();
    collect_times();
    part.quality = trees_[p]->queued_quality();
    part.quality_ready = true;
    return part.quality;
  }

  std::vector<int32_t> triangle_order() override {
    stream_->synchronize();  // a build may still be queued
    std::vector<int32_t> order(static_cast<size_t>(trees_.at(0)->shape().leaf_count));
    if (!order.empty())
      SNAG_CUDA_CHECK(cudaMemcpy(order.data(), trees_[0]->view().triangle_at,
                                 order.size() * sizeof(int32_t), cudaMemcpyDeviceToHost));
    return order;
  }

  std::vector<geom::Box3f> node_boxes() override {
    stream_->synchronize();  // a build or a refit may still be queued
    const int32_t n = trees_.at(0)->shape().leaf_count;
    std::vector<geom::Box3f> boxes(n > 0 ? static_cast<size_t>(2 * n - 1) : 0);
    if (!boxes.empty())
      SNAG_CUDA_CHECK(cudaMemcpy(boxes.data(), trees_[0]->view().boxes,
                                 boxes.size() * sizeof(geom::Box3f), cudaMemcpyDeviceToHost));
    return boxes;
  }

  detect::FilteredFrame detect_checks(std::span<const int32_t> degenerate, detect::FilterUse use,
                                      std::span<const int32_t> checks) override;

 protected:
  int32_t part_count() const override { return topology_ ? topology_->part_count() : 0; }
  int32_t check_count() const override {
    return topology_ ? static_cast<int32_t>(topology_->checks.size()) : 0;
  }

 private:
  /// What one part's device data fits, as versions: each set of positions gives every part
  /// that moved a new number (versions_issued_), so equal numbers mean equal positions.
  struct PartState {
    uint64_t version = 0;         ///< of the current positions
    uint64_t tree_version = 0;    ///< the tree's boxes fit this version
    uint64_t planes_version = 0;  ///< planes_ of the part's triangles fit this version
    bool tree_built = false;
    bool quality_ready = false;
    double quality = 0;
  };

  int32_t part_begin(int32_t p) const { return topology_->layout.triangle_begin[p]; }
  int32_t part_size(int32_t p) const {
    return topology_->layout.triangle_begin[p + 1] - topology_->layout.triangle_begin[p];
  }
  /// Part p's triangles over a whole frame's positions: its tree's triangle ids are local.
  mesh::MeshView part_mesh(int32_t p, const geom::Vec3d* positions) const {
    return {positions, topo_.triangles.data() + part_begin(p), topo_.vertex_count, part_size(p)};
  }

  /// A frame's positions on the device and the version of each part they hold: the current
  /// frame's, or the staged one's when its work is queued ahead (queue_ahead).
  struct FrameView {
    const geom::Vec3d* positions = nullptr;
    std::vector<uint64_t> versions;  ///< per part
    bool operator==(const FrameView&) const = default;
  };
  FrameView current_view() const { return {current_positions_, part_versions()}; }

  /// `moved` as the rest of the backend reads it: empty (every part moved) unless it has an
  /// entry per part. A caller's list of another length (a next frame whose parts split or
  /// merged) was read past its end.
  std::span<const uint8_t> moved_per_part(std::span<const uint8_t> moved) const {
    return moved.size() == part_.size() ? moved : std::span<const uint8_t>{};
  }
  /// The versions of a frame whose parts moved as `moved` says (empty: all of them).
  std::vector<uint64_t> next_versions(std::span<const uint8_t> moved) {
    std::vector<uint64_t> versions(part_.size());
    for (size_t p = 0; p < part_.size(); ++p)
      versions[p] = moved.empty() || moved[p] || part_[p].version == 0 ? ++versions_issued_
                                                                       : part_[p].version;
    return versions;
  }
  /// Whether two `moved` lists say the same of every part (an empty one: every part moved).
  bool same_moved(std::span<const uint8_t> a, const std::vector<uint8_t>& b) const {
    for (size_t p = 0; p < part_.size(); ++p) {
      const bool in_a = a.empty() || a[p], in_b = b.empty() || b[p];
      if (in_a != in_b) return false;
    }
    return true;
  }

  /// Copies into `slot` the vertices of every part whose version there is not `versions'`
  /// (neighbouring parts in one copy), on `s`, and records the slot's new versions. Positions
  /// staged in pinned memory (host_staging) go straight across; others through the slot's own
  /// pinned buffer, copied into it here.
  void copy_stale_parts(std::span<const geom::Vec3d> positions, int slot,
                        const std::vector<uint64_t>& versions, cudaStream_t s) {
    const auto& vertex_begin = topology_->layout.vertex_begin;
    const int32_t parts = static_cast<int32_t>(part_.size());
    const bool staged = staging_ && staging_->holds(positions);
    for (int32_t p = 0; p < parts;) {
      if (slot_version_[slot][p] == versions[p]) {
        ++p;
        continue;
      }
      int32_t q = p;
      while (q < parts && slot_version_[slot][q] != versions[q])
        slot_version_[slot][q] = versions[q], ++q;
      const size_t first = static_cast<size_t>(vertex_begin[p]);
      const size_t count = static_cast<size_t>(vertex_begin[q]) - first;
      if (count) {
        const geom::Vec3d* source = positions.data() + first;
        if (!staged) {
          copy_for_transfer(positions_host_[slot].data() + first, source,
                            count * sizeof(geom::Vec3d));
          source = positions_host_[slot].data() + first;
        }
        SNAG_CUDA_CHECK(cudaMemcpyAsync(positions_[slot].data() + first, source,
                                        count * sizeof(geom::Vec3d), cudaMemcpyHostToDevice, s));
        // At once, transfer by transfer: should a later one fail, the frame (and with it the
        // staging buffer) may be dropped, and the buffer is not written before this one is done.
        if (staged) staging_->note_read(positions, s);
      }
      p = q;
    }
  }

  cudaStream_t stream() const { return stream_->get(); }

  /// Copies the staged frame into pinned memory (unless it is in the staging's already) and
  /// queues its transfer, when stage_part_positions
  /// left that to do: from this frame's scan or detect, while the staged span is valid (until
  /// the next set_part_positions), or from that set when it is given the same span. A staged
  /// frame that is not the next one set is forgotten without being read (drop_staged_positions):
  /// its span may be gone by then.
  void copy_staged_positions() {
    if (!staged_copy_pending_) return;
    staged_copy_pending_ = false;
    const int slot = 1 - positions_slot_;
    const cudaStream_t upload = upload_stream_->get();
    copy_stale_parts({staged_data_, staged_size_}, slot, staged_version_, upload);
    pinned_copied_[slot].record(upload);
    staged_ready_.record(upload);
  }

  /// Forgets a staged frame that was not the next one set, once its copy (which writes the
  /// slot a new frame will use) is done; one not yet copied is simply forgotten.
  void drop_staged_positions() {
    if (!staged_) return;
    staged_ = false;
    release_recorded_ = false;  // work may have been queued ahead on the slot it was to fill
    if (staged_copy_pending_) {
      staged_copy_pending_ = false;
      return;
    }
    upload_stream_->synchronize();
  }

  void require_topology() const {
    if (!topology_) throw InternalError("cuda backend: no topology set");
  }

  /// Queues part p's refit to `view`'s positions; `timed`: between the refit timer's events,
  /// which a refit queued ahead by the scan leaves out (the scan's timer covers it, and
  /// refit_part() then reports 0), so that the scan's launches follow one another with no other
  /// step between them.
  void queue_refit(int32_t p, bool timed, const FrameView& view) {
    if (part_size(p) == 0) return;  // built empty: nothing to refit
    order_after_ahead();
    note_reads(view.positions);
    if (timed) refit_timer_.start(stream());
    trees_[p]->refit(part_mesh(p, view.positions), planes_.data() + part_begin(p), stream());
    if (timed) {
      refit_timer_.stop_async(stream());
      refit_pending_ = true;
    }
    ++tree_changes_;
    part_[p].tree_version = view.versions[p];
    part_[p].planes_version = view.versions[p];
    part_[p].quality_ready = false;
  }
  /// Main-stream work queued from here on runs after the side-stream work queued ahead (the
  /// scan reads the staged slot; the qualities read the trees and their quality scratch), so
  /// that a call out of a checker's order (a tree built, refit or measured, another frame set)
  /// does not run beside it.
  void order_after_ahead() {
    if (ahead_.queued) SNAG_CUDA_CHECK(cudaStreamWaitEvent(stream(), ahead_timer_.stop_event(), 0));
  }
  /// Work that reads `positions` is being queued: when they are the slot released by
  /// queue_ahead, that release came too early for the next staged copy.
  void note_reads(const geom::Vec3d* positions) {
    if (release_recorded_ && positions == positions_[released_slot_].data())
      release_recorded_ = false;
  }

  /// Whether part p has a tree built that does not fit `view`'s positions.
  bool needs_refit(int32_t p, const FrameView& view) const {
    return part_[p].tree_built && part_[p].tree_version != view.versions[p] && part_size(p) > 0;
  }

  /// A frame's work up to its scan's wait, for `view`: the refits of the built trees that do
  /// not fit it and the detect queued behind them (speculate_detect) on the main stream, and on
  /// the side stream the scan of `parts` and those trees' qualities, into host memory. The walks
  /// need the refit's boxes and planes, not the scan or the quality: the side stream waits for
  /// the frame's positions (`timer`'s start) for the scan and for the refits (an event) for the
  /// qualities, and is queued last, once the host has queued the main stream's work, so that
  /// the walks do not wait for it. `timer` stops when the side stream is done. Returns the parts
  /// refit.
  std::vector<int32_t> queue_frame(std::span<const int32_t> parts, const FrameView& view,
                                   EventTimer& timer) {
    const cudaStream_t s = stream(), side = side_stream_->get();
    note_reads(view.positions);
    timer.start(s);
    std::vector<int32_t> refit;
    for (int32_t p = 0; p < static_cast<int32_t>(part_.size()); ++p)
      if (needs_refit(p, view)) refit.push_back(p);
    for (int32_t p : refit) queue_refit(p, /*timed=*/false, view);  // its time is the scan's
    refits_queued_.record(s);
    speculate_detect(view);

    SNAG_CUDA_CHECK(cudaStreamWaitEvent(side, timer.start_event(), 0));
    // One launch per part; the last publishes the counts into host memory (none: no launch,
    // and the counts stay zero).
    size_t last_scanned = parts.size();
    for (size_t i = 0; i < parts.size(); ++i)
      if (part_size(parts[i]) > 0) last_scanned = i;
    ScanCounts* const counts = scan_counts_host_.data();
    *counts = {};
    // A scan cut short (an exception between its launches and its counts read) or whose counts
    // were wrong may have left counts in the counters, which only a whole scan zeroes: cleared
    // first.
    if (scan_pending_)
      SNAG_CUDA_CHECK(cudaMemsetAsync(scan_counters_.data(), 0, sizeof(ScanCounters), side));
    scan_pending_ = true;
    for (size_t i = 0; i < parts.size(); ++i)
      if (part_size(parts[i]) > 0)
        launch_scan_degenerate(view.positions, topo_.triangles.data(), part_begin(parts[i]),
                               part_size(parts[i]), mapped(scan_degenerate_host_.data()),
                               mapped(scan_uncertain_host_.data()), topo_.triangle_count,
                               scan_counters_.data(), i == last_scanned ? mapped(counts) : nullptr,
                               side);
    if (!refit.empty()) refits_queued_.wait_on(side);
    for (int32_t p : refit) trees_[p]->queue_quality(side);
    timer.stop_async(side);
    return refit;
  }

  /// Stage times whose stop events the stream has passed (called after a wait).
  void collect_times() const {
    if (upload_pending_) times_.upload = upload_timer_.elapsed();
    if (build_pending_) times_.build = build_timer_.elapsed();
    if (refit_pending_) times_.refit = refit_timer_.elapsed();
    upload_pending_ = build_pending_ = refit_pending_ = false;
  }

  /// Result buffers for at least these counts. Never shrinks, so a sequence allocates only
  /// while its counts grow; the pair set's table is a power of two at least twice the pairs.
  void ensure_result_capacity(uint64_t hits, uint64_t uncertain, uint64_t duplicates,
                              uint64_t pairs, uint64_t listed, uint64_t subwalks) {
    listed_.reserve(listed);
    screened_.reserve(listed);
    subwalks_.reserve(subwalks);
    hits_.reserve(hits);
    uncertain_.reserve(uncertain);
    duplicates_.reserve(duplicates);
    pair_keys_.reserve(pairs);
    pair_status_.reserve(pairs);
    uint64_t table = 1;
    while (table < 2 * pairs) table <<= 1;
    table_.reserve(table);
  }

  /// The pairs a check may list: every one stored may pass the screen, so the screened list
  /// holds as many (the two are reserved together).
  uint64_t candidate_capacity() const { return std::min(listed_.capacity(), screened_.capacity()); }

  /// With some slack, so that a sequence whose counts creep up does not run every frame twice.
  static uint64_t grown(uint64_t count) { return count + count / 2 + 1024; }

  /// Buffers for a run's counts with slack (grown), and the grids of the subwalks, the whole
  /// pair tests, the expansion and the ranking sized for them. Growing
  /// discards the buffers' contents: after a frame's results are read, or before a run again.
  void fit_counts(const FrameCounters& c) {
    // c.expanded + c.duplicates bounds the pairs of every stored hit.
    ensure_result_capacity(grown(c.hits), grown(c.uncertain), grown(c.duplicates),
                           grown(c.expanded + c.duplicates), grown(c.listed_most),
                           grown(c.subwalks_most));
    subwalks_expected_ = grown(c.subwalks_most);
    screened_expected_ = grown(c.screened_most);
    expand_expected_ = grown(2 * c.hits + c.duplicates);
    // Any count fits the ranking's grid (it strides), but a grid much too small ranks slowly:
    // sized for the larger of this frame's count and seven eighths of what it was sized for,
    // so that a sequence whose frames alternate between many results and none (the 1M cloth's
    // two bench frames: thousands of uncertain tests, then none) keeps the larger grid, where
    // one block ranked thousands of keys in turn (0.1 ms), and a single heavy frame is
    // forgotten within a few dozen.
    finish_expected_ =
        std::max<uint64_t>(std::max(c.pairs, c.uncertain), finish_expected_ - finish_expected_ / 8);
  }

  /// frame.pairs and frame.kind_certain from `count` (a << pair_bits_ | b) keys and their
  /// statuses (bit 0: touching, bit 1: certain), key_and_status(i) giving the i-th. Returns
  /// how many kinds are not certain.
  template <class KeyAndStatus>
  int64_t decode_pairs(size_t count, detect::FilteredFrame& frame,
                       KeyAndStatus&& key_and_status) const {
    frame.pairs.resize(count);
    frame.kind_certain.resize(count);
    // Through local pointers: with frame.pairs[i] the compiler reloads the vector's storage
    // after every store to kind_certain (bytes, which may alias anything).
    detect::FacePair* const pairs = frame.pairs.data();
    uint8_t* const certain = frame.kind_certain.data();
    const int bits = pair_bits_;
    const uint64_t mask = (uint64_t{1} << bits) - 1;
    int64_t uncertain_kinds = 0;
    for (size_t i = 0; i < count; ++i) {
      const auto [key, status] = key_and_status(i);
      pairs[i] = {static_cast<int32_t>(key >> bits), static_cast<int32_t>(key & mask),
                  static_cast<detect::PairKind>(status & 1)};
      certain[i] = static_cast<uint8_t>(status >> 1);
      uncertain_kinds += 1 - (status >> 1);
    }
    return uncertain_kinds;
  }
  /// frame.uncertain from `count` (edge << 32 | triangle) keys.
  static void decode_tasks(const uint64_t* keys, size_t count, detect::FilteredFrame& frame) {
    frame.uncertain.resize(count);
    detect::EdgeTriangleTask* const tasks = frame.uncertain.data();
    for (size_t i = 0; i < count; ++i)
      tasks[i] = {static_cast<int32_t>(keys[i] >> 32), static_cast<int32_t>(keys[i] & 0xffffffffu)};
  }

  /// The frame's degenerate flags and edge ownership on the device.
  const uint8_t* prepare_degenerate(std::span<const int32_t> degenerate);
  /// Edge ownership on the device for the degenerate triangles flagged there (flagged_).
  const uint8_t* flagged_owned_edges() const {
    return flagged_.empty() ? topo_.owned_edges.data() : topo_.frame_owned_edges.data();
  }
  void queue_detect(detect::FilterUse use, std::span<const int32_t> checks, const uint8_t* owned,
                    const FrameView& view);
  void speculate_detect(const FrameView& view);
  void queue_ahead();
  std::vector<uint64_t> part_versions() const {
    std::vector<uint64_t> versions(part_.size());
    for (size_t p = 0; p < part_.size(); ++p) versions[p] = part_[p].version;
    return versions;
  }

  /// A detect_checks call: its checks and the filter's use.
  struct DetectCall {
    bool valid = false;
    detect::FilterUse use = detect::FilterUse::certify;
    std::vector<int32_t> checks;
  };
  /// A detect queued ahead by the scan (speculate_detect) and what it assumed.
  struct Speculation {
    bool queued = false;
    bool ahead = false;  ///< queued by queue_ahead
    DetectCall call;
    std::vector<int32_t> degenerate;  ///< flagged_ then
    uint64_t tree_changes = 0;        ///< tree_changes_ then
    FrameView view;                   ///< the frame it checks
  };

  SelectDevice select_;
  int device_ = 0;
  std::string device_name_;
  /// Pinned buffers a caller stages frames' positions in (host_staging): copy_stale_parts
  /// transfers spans inside them directly.
  std::shared_ptr<PinnedStaging> staging_;
  std::unique_ptr<Stream> stream_;
  EventTimer timer_, span_timer_;
  mutable StageTimes times_;
  const detect::Topology* topology_ = nullptr;
  DeviceTopology topo_;
  std::vector<std::unique_ptr<DeviceTree>> trees_;  // per part
  std::vector<PartState> part_;
  uint64_t versions_issued_ = 0;
  bool level_by_level_refit_ = false;
  std::vector<std::unique_ptr<EventTimer>> check_timers_;  // per check, when several run
  // Positions in two slots, so that the next frame is copied in while the current one is
  // checked (stage_positions); positions_slot_ is the current frame's.
  DeviceBuffer<geom::Vec3d> positions_[2], resident_;
  PinnedBuffer<geom::Vec3d> positions_host_[2];
  int positions_slot_ = 0;
  std::vector<uint64_t> slot_version_[2];  // per slot, per part: the version it holds (0: none)
  bool on_resident_ = false;               // current_positions_ is a resident frame
  std::unique_ptr<Stream> upload_stream_;
  // The scan and the qualities queued ahead (scan_degenerate_parts), beside the main stream's
  // refits and walks; the host waits for it before each scan returns.
  std::unique_ptr<Stream> side_stream_;
  Event refits_queued_;            // the main stream's refits queued ahead by a scan
  Event pinned_copied_[2];         // the last copy out of each pinned buffer
  Event slot_released_;            // main-stream work queued before a staged copy
  bool release_recorded_ = false;  // slot_released_ recorded by queue_ahead for the next staging
  int released_slot_ = 0;          // the slot it released
  Event staged_ready_;             // the staged copy
  bool staged_ = false;
  bool staged_copy_pending_ = false;  // staged_, its host copy not made yet (copy_staged_positions)
  const geom::Vec3d* staged_data_ = nullptr;  // the staged frame, as the caller holds it
  size_t staged_size_ = 0;
  std::vector<uint8_t> staged_moved_;     // as the caller said
  std::vector<uint64_t> staged_version_;  // the versions it gets when set
  const geom::Vec3d* current_positions_ = nullptr;
  int resident_count_ = 0;
  DeviceBuffer<geom::PlaneCoefficients> planes_;
  // Per triangle of a part with fans, as its tree's leaf positions: NeighborDrop's later;
  // leaf_position_ is launch_later_neighbors' scratch.
  DeviceBuffer<uint64_t> later_neighbors_;
  DeviceBuffer<int32_t> leaf_position_;
  PinnedBuffer<int32_t> scan_degenerate_host_, scan_uncertain_host_;  // written by the scan kernel
  std::vector<int32_t> flagged_;  ///< degenerate ids flagged on the device for the last frame
  DeviceBuffer<FrameCounters> counters_;
  // The detect's counts, pairs and uncertain tests in host memory, written by finish_kernel (or
  // copied, for large frames): two sets, so that a detect queued ahead (queue_ahead) writes one
  // while the host decodes the other. results_set_ is the one the next run writes.
  PinnedBuffer<FrameCounters> counters_host_[2];
  PinnedBuffer<uint64_t> host_pairs_[2], host_uncertain_[2];  // pairs: keys with their status
  HostResults host_results_[2];                               // device addresses of each set
  int results_set_ = 0;
  DeviceBuffer<ScanCounters> scan_counters_;  // zero between scans (the scan leaves them so)
  bool scan_pending_ = false;  // a scan's launches queued, its counts not yet read and accepted
  PinnedBuffer<ScanCounts> scan_counts_host_;  // the last scan's counts, written by its kernel
  DetectCall last_detect_;
  Speculation speculation_;
  /// The next frame's work queued at the end of a detect (queue_ahead) and what it assumed.
  struct Ahead {
    bool queued = false;
    std::vector<int32_t> parts;  ///< scanned
    std::vector<int32_t> refit;  ///< refit, their qualities queued
    FrameView view;              ///< the staged frame
    uint64_t tree_changes = 0;   ///< tree_changes_ then
  };
  Ahead ahead_;
  AheadTaken ahead_taken_;
  EventTimer ahead_timer_;     // from the staged positions ready to the ahead's side stream done
  bool scanned_ = false;       // the current frame's positions went through a scan
  uint64_t tree_changes_ = 0;  // builds and refits queued: a detect queued ahead read the trees
  unsigned max_blocks_ = 1;
  EventTimer detect_timer_;
  DeviceBuffer<uint64_t> listed_;    // a check's candidate pairs, from its walks to its tests
  DeviceBuffer<uint64_t> screened_;  // those past the screen, to the whole test (as many slots)
  DeviceBuffer<uint64_t> subwalks_;  // a check's walks under the split level, from the walks
                                     // above it to the subwalk kernel
  uint64_t subwalks_expected_ = 1;   // the last frame's most subwalks, with slack
  uint64_t screened_expected_ = 1;   // its most screened pairs, with slack
  uint64_t expand_expected_ = 1;     // its expansion's items (two per hit), with slack
  uint64_t finish_expected_ = 1;     // its pairs or uncertain tests, the more (see fit_counts)
  DeviceBuffer<uint64_t> hits_, uncertain_, duplicates_;
  // The pair set (PairSet) and the large-frame path's sort buffers.
  DeviceBuffer<unsigned long long> table_;
  DeviceBuffer<uint64_t> pair_keys_, keys_alt_, tasks_alt_;
  DeviceBuffer<uint8_t> pair_status_, status_alt_;
  DeviceBuffer<unsigned char> temp_;
  DeviceBuffer<unsigned> finish_ranks_, finish_tickets_;  // FinishScratch, zero between runs
  // Results in host memory: written by finish_kernel (small frames) or copied (large ones).
  PinnedBuffer<uint64_t> keys_host_, uncertain_host_;
  PinnedBuffer<uint8_t> status_host_;
  // Stage timers whose stop may still be queued: read (and waited for) by collect_times().
  mutable EventTimer upload_timer_, build_timer_, refit_timer_;
  mutable bool upload_pending_ = false, build_pending_ = false, refit_pending_ = false;
  EventTimer narrow_timer_;
  unsigned long long finish_limit_ = kFinishLimit;
  int64_t initial_capacity_ = 1 << 16;
  int pair_bits_ = 1, edge_bits_ = 1;
};

const uint8_t* CudaBackendImpl::prepare_degenerate(std::span<const int32_t> degenerate) {
  const cudaStream_t s = stream();
  const size_t n = static_cast<size_t>(topo_.triangle_count);
  const bool same = flagged_.size() == degenerate.size() &&
                    std::equal(flagged_.begin(), flagged_.end(), degenerate.begin());
  if (!same) {
    if (!flagged_.empty()) SNAG_CUDA_CHECK(cudaMemsetAsync(topo_.degenerate.data(), 0, n, s));
    if (!degenerate.empty()) {
      SNAG_CUDA_CHECK(cudaMemcpyAsync(topo_.degenerate_list.data(), degenerate.data(),
                                      degenerate.size_bytes(), cudaMemcpyHostToDevice, s));
      launch_flag_degenerate(topo_.degenerate_list.data(), static_cast<int32_t>(degenerate.size()),
                             topo_.degenerate.data(), s);
      // Degenerate triangles own nothing this frame: their edges go to the next incident face.
      const std::vector<uint8_t> owned = detect::ownership_without(*topology_, degenerate);
      SNAG_CUDA_CHECK(cudaMemcpyAsync(topo_.frame_owned_edges.data(), owned.data(), n,
                                      cudaMemcpyHostToDevice, s));
      stream_->synchronize();  // `owned` is a local: the copy must finish before it goes
    }
    flagged_.assign(degenerate.begin(), degenerate.end());
  }
  return flagged_owned_edges();
}

/// One run of a frame's checks queued whole, without a wait: planes where no refit or build
/// computed them, then per check its walk and pair tests, the expansion into the pair set, and
/// (up to kFinishLimit results) the ranking straight into host memory. Buffers are
/// sized by earlier frames; a count past a capacity is counted, not stored (see detect_checks).
void CudaBackendImpl::queue_detect(detect::FilterUse use, std::span<const int32_t> checks,
                                   const uint8_t* owned, const FrameView& view) {
  const cudaStream_t s = stream();
  const int32_t n = topo_.triangle_count;
  note_reads(view.positions);
  detect_timer_.start(s);
  for (int32_t c : checks)
    for (int32_t p : {topology_->checks[c].a, topology_->checks[c].b}) {
      PartState& part = part_[p];
      if (part.planes_version == view.versions[p] || part_size(p) == 0) continue;
      launch_planes(view.positions, topo_.triangles.data() + part_begin(p), part_size(p),
                    planes_.data() + part_begin(p), s);
      part.planes_version = view.versions[p];
    }
  // The fans of the parts checked against themselves, which their subwalks and pair tests read
  // (each computed in its part's walk kernel: FanJob).
  const bool fans = use == detect::FilterUse::certify && topo_.has_fans;
  // Fan-cleared neighbours left out of the lists, in frames with no degenerate triangle: a
  // clear fan's triangles have certified nonzero area, but `--exact off` may still flag one,
  // and then some of the pairs left out would not have been candidates.
  NeighborDrop drop;
  if (fans && flagged_.empty())
    drop = {later_neighbors_.data(), topo_.triangles.data(), topo_.fan_clear.data()};
  PairInputs inputs;
  inputs.frame = {view.positions, planes_.data(), fans ? topo_.fan_clear.data() : nullptr};
  inputs.topology.triangles = topo_.triangles.data();
  inputs.topology.edges = topo_.edges.data();
  inputs.topology.triangle_edges = topo_.triangle_edges.data();
  inputs.topology.owned_edges = owned;
  inputs.topology.triangle_count = n;
  inputs.topology.edge_count = topo_.edge_count;
  inputs.degenerate = topo_.degenerate.data();
  ResultBuffers results;
  results.hits = hits_.data();
  results.uncertain = uncertain_.data();
  results.duplicates = duplicates_.data();
  results.hit_capacity = hits_.capacity();
  results.uncertain_capacity = uncertain_.capacity();
  results.duplicate_capacity = duplicates_.capacity();
  results.counters = counters_.data();
  results.edge_face_offsets = topo_.edge_face_offsets.data();
  PairSet set{table_.data(), table_.capacity() - 1, pair_keys_.data(), pair_status_.data(),
              pair_keys_.capacity()};
  const CandidateList listed{listed_.data(), candidate_capacity(), screened_.data(),
                             screened_expected_};
  const SubwalkList subwalks{subwalks_.data(), subwalks_.capacity(), subwalks_expected_};
  HostResults out = host_results_[results_set_];
  out.limit = finish_limit_;
  launch_clear_frame(counters_.data(), table_.data(), table_.capacity(), s);
  const bool time_each = checks.size() > 1;
  for (size_t i = 0; i < checks.size(); ++i) {
    const detect::PartCheck check = topology_->checks[checks[i]];
    if (time_each) check_timers_[i]->start(s);
    // Each check lists its subwalks, candidates and screened pairs from the start of their
    // lists (the first finds them cleared with the rest).
    static_assert(offsetof(FrameCounters, subwalks) ==
                      offsetof(FrameCounters, listed) + sizeof(unsigned long long) &&
                  offsetof(FrameCounters, screened) ==
                      offsetof(FrameCounters, listed) + 2 * sizeof(unsigned long long));
    if (i > 0)
      SNAG_CUDA_CHECK(
          cudaMemsetAsync(&counters_.data()->listed, 0, 3 * sizeof(unsigned long long), s));
    if (check.self()) {
      FanJob part_fans;
      if (fans) {
        const int32_t first = topology_->layout.vertex_begin[check.a];
        part_fans = {view.positions,
                     planes_.data(),
                     {topo_.fan_begin.data(), topo_.fan_steps.data()},
                     first,
                     topology_->layout.vertex_begin[check.a + 1] - first,
                     topo_.fan_clear.data()};
      }
      if (part_size(check.a) > 0)
        launch_self_check(trees_[check.a]->view(), part_begin(check.a), inputs, part_fans, drop,
                          subwalks, listed, results, use, max_blocks_, s);
    } else {
      // One thread per leaf of the larger part, walking the smaller one's tree.
      const bool a_larger = part_size(check.a) >= part_size(check.b);
      const int32_t big = a_larger ? check.a : check.b, small = a_larger ? check.b : check.a;
      launch_cross_check(trees_[big]->view(), part_begin(big), trees_[small]->view(),
                         part_begin(small), inputs, subwalks, listed, results, use, max_blocks_, s);
    }
    if (time_each) check_timers_[i]->stop_async(s);
  }
  narrow_timer_.stop_async(s);
  launch_expand(hits_.data(), hits_.capacity(), duplicates_.data(), duplicates_.capacity(),
                expand_expected_, counters_.data(), topo_.edge_face_offsets.data(),
                topo_.edge_faces.data(), topo_.degenerate.data(), pair_bits_, view.positions,
                topo_.triangles.data(), set, max_blocks_, s);
  launch_finish(counters_.data(), set, uncertain_.data(), uncertain_.capacity(), finish_expected_,
                {finish_ranks_.data(), finish_tickets_.data()}, out, s);
  detect_timer_.stop_async(s);
}

/// Queued before the scan's wait (queue_frame), so that the device goes on from the refits to
/// the checks while the host reads the scan and decides: the last frame's checks, with its
/// filter use and its degenerate triangles (usually none, and then this frame's scan finds
/// none either), over `view`'s positions. Only when every checked part's tree fits them (the
/// refits queued before). detect_checks takes it when its call turns out to be the one assumed
/// on those positions and no tree was built or refit in between; else it queues the frame
/// again (the stream orders the runs, and each run starts by clearing what it fills).
void CudaBackendImpl::speculate_detect(const FrameView& view) {
  speculation_.queued = false;
  if (!last_detect_.valid) return;
  for (int32_t c : last_detect_.checks)
    for (int32_t p : {topology_->checks[c].a, topology_->checks[c].b})
      if (part_size(p) > 0 && (!part_[p].tree_built || part_[p].tree_version != view.versions[p]))
        return;
  queue_detect(last_detect_.use, last_detect_.checks, flagged_owned_edges(), view);
  speculation_.queued = true;
  speculation_.ahead = false;
  speculation_.call = last_detect_;
  speculation_.degenerate = flagged_;
  speculation_.tree_changes = tree_changes_;
  speculation_.view = view;
}

/// Frame k + 1's work, queued at the end of frame k's detect once its results are in host
/// memory, when the caller staged k + 1 and frame k went through a scan (a checker's frame):
/// what k + 1's scan would queue (queue_frame: refits, the speculated detect, the scan and the
/// qualities) over the staged positions, so that the device goes on from k's checks to k + 1's
/// while the host decodes k's results, resolves its uncertain tests and takes the next frame
/// (a checker's frame spends ~60 us of host time around the device's ~110 us at 36K,
/// cuda/NOTES.md). k + 1's scan and detect take it when their calls turn out to be the ones
/// assumed; else they wait for it and queue their own. Its detect writes the other set of host
/// results, the one k's are not decoded from; the refits change the trees under a frame whose
/// checks are done (a call for k after this refits them back: needs_refit).
void CudaBackendImpl::queue_ahead() {
  if (!staged_ || staged_copy_pending_ || on_resident_ || !scanned_ || !last_detect_.valid) return;
  const cudaStream_t s = stream();
  // The current frame's work on its slot ends here: the frame after the staged one may be
  // copied into it while the staged one is checked (stage_part_positions).
  slot_released_.record(s);
  release_recorded_ = true;
  released_slot_ = positions_slot_;
  staged_ready_.wait_on(s);
  const FrameView view{positions_[1 - positions_slot_].data(), staged_version_};
  std::vector<int32_t> parts;
  for (int32_t p = 0; p < static_cast<int32_t>(part_.size()); ++p)
    if (staged_moved_.empty() || staged_moved_[p]) parts.push_back(p);
  results_set_ = 1 - results_set_;
  ahead_.refit = queue_frame(parts, view, ahead_timer_);
  speculation_.ahead = speculation_.queued;
  ahead_.queued = true;
  ahead_.parts = std::move(parts);
  ahead_.view = view;
  ahead_.tree_changes = tree_changes_;
}

detect::FilteredFrame CudaBackendImpl::detect_checks(std::span<const int32_t> degenerate,
                                                     detect::FilterUse use,
                                                     std::span<const int32_t> checks) {
  require_topology();
  detect::FilteredFrame frame;
  if (topo_.triangle_count == 0) return frame;
  const auto start = Clock::now();
  const FrameView view = current_view();
  // Trees refit ahead to the staged frame (queue_ahead) when this frame's checks are asked
  // again: refit back (which voids the speculation).
  for (int32_t c : checks)
    for (int32_t p : {topology_->checks[c].a, topology_->checks[c].b})
      if (needs_refit(p, view)) queue_refit(p, /*timed=*/true, view);
  const bool speculated = speculation_.queued && speculation_.call.use == use &&
                          std::ranges::equal(speculation_.call.checks, checks) &&
                          std::ranges::equal(speculation_.degenerate, degenerate) &&
                          speculation_.tree_changes == tree_changes_ && speculation_.view == view;
  speculation_.queued = false;
  ahead_taken_.detects += speculated && speculation_.ahead;
  // The set the run writes in host memory; a detect queued ahead writes the other one.
  const int set = results_set_;
  const uint8_t* owned = prepare_degenerate(degenerate);
  if (!speculated) queue_detect(use, checks, owned, view);
  last_detect_ = {true, use, std::vector<int32_t>(checks.begin(), checks.end())};

  copy_staged_positions();  // when no scan came first
  // The one wait. When a buffer overflowed, the counts say by how much: grow, run again. No
  // pair is lost, and a sequence allocates only while its counts grow.
  FrameCounters c{};
  for (;;) {
    detect_timer_.elapsed();
    c = *counters_host_[set].data();
    if (c.hits <= hits_.capacity() && c.uncertain <= uncertain_.capacity() &&
        c.duplicates <= duplicates_.capacity() && c.pairs <= pair_keys_.capacity() &&
        c.listed_most <= candidate_capacity() && c.subwalks_most <= subwalks_.capacity())
      break;
    // The next run fits, but for the stages after one that overflowed: a subwalk list that
    // overflowed left pairs unlisted, a candidate list that overflowed left hits unfound, so
    // each undercounts the stages after it, and a frame can take up to four runs. None is
    // ever lost.
    fit_counts(c);
    queue_detect(use, checks, owned, view);
  }
  collect_times();
  {
    float ms = 0;
    SNAG_CUDA_CHECK(
        cudaEventElapsedTime(&ms, detect_timer_.start_event(), narrow_timer_.stop_event()));
    times_.traverse = ms;
  }
  times_.classify = detect_timer_.elapsed() - times_.traverse;
  frame.traverse_seconds = seconds_since(start);
  // Device time of each check (a single one: the traversal's, memsets included).
  for (size_t i = 0; i < checks.size(); ++i)
    frame.check_seconds.push_back(
        (checks.size() > 1 ? check_timers_[i]->elapsed() : times_.traverse) * 1e-3);
  frame.candidate_pairs = static_cast<int64_t>(c.candidates);

  const auto classify_start = Clock::now();
  // Frames too large for one block: CUB's device-wide sorts, now that the counts are known.
  const bool large_pairs = c.pairs > finish_limit_, large_tasks = c.uncertain > finish_limit_;
  const cudaStream_t s = stream();
  const int key_bits = 2 * pair_bits_, task_bits = 32 + edge_bits_;
  if (large_pairs || large_tasks) {
    timer_.start(s);
    keys_alt_.reserve(std::max<size_t>(c.pairs, 1));
    status_alt_.reserve(std::max<size_t>(c.pairs, 1));
    tasks_alt_.reserve(std::max<size_t>(c.uncertain, 1));
    size_t need = 0, bytes = 0;
    if (large_pairs) {
      SNAG_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(
          nullptr, bytes, pair_keys_.data(), keys_alt_.data(), pair_status_.data(),
          status_alt_.data(), static_cast<int64_t>(c.pairs), 0, key_bits, s));
      need = std::max(need, bytes);
    }
    if (large_tasks) {
      SNAG_CUDA_CHECK(
          cub::DeviceRadixSort::SortKeys(nullptr, bytes, uncertain_.data(), tasks_alt_.data(),
                                         static_cast<int64_t>(c.uncertain), 0, task_bits, s));
      need = std::max(need, bytes);
    }
    temp_.reserve(std::max<size_t>(need, 1));
    if (large_pairs) {
      keys_host_.reserve(c.pairs);
      status_host_.reserve(c.pairs);
      bytes = temp_.capacity();
      SNAG_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(
          temp_.data(), bytes, pair_keys_.data(), keys_alt_.data(), pair_status_.data(),
          status_alt_.data(), static_cast<int64_t>(c.pairs), 0, key_bits, s));
      SNAG_CUDA_CHECK(cudaMemcpyAsync(keys_host_.data(), keys_alt_.data(),
                                      c.pairs * sizeof(uint64_t), cudaMemcpyDeviceToHost, s));
      SNAG_CUDA_CHECK(cudaMemcpyAsync(status_host_.data(), status_alt_.data(), c.pairs,
                                      cudaMemcpyDeviceToHost, s));
    }
    if (large_tasks) {
      uncertain_host_.reserve(c.uncertain);
      bytes = temp_.capacity();
      SNAG_CUDA_CHECK(
          cub::DeviceRadixSort::SortKeys(temp_.data(), bytes, uncertain_.data(), tasks_alt_.data(),
                                         static_cast<int64_t>(c.uncertain), 0, task_bits, s));
      SNAG_CUDA_CHECK(cudaMemcpyAsync(uncertain_host_.data(), tasks_alt_.data(),
                                      c.uncertain * sizeof(uint64_t), cudaMemcpyDeviceToHost, s));
    }
    timer_.stop_async(s);
    times_.classify += timer_.elapsed();
  }
  // Next frames start with this one's counts and some slack, so that creeping counts rarely
  // run a frame twice (buffers never shrink). Growing discards the device buffers' contents,
  // which this frame's results (in host memory now) no longer need.
  fit_counts(c);
  // The staged frame's work, queued before this frame's results are decoded below.
  queue_ahead();

  // A frame's results as finish_kernel wrote them (pairs with their status above the key), or
  // the device-wide sorts' keys and statuses.
  const auto pair_count = static_cast<size_t>(c.pairs);
  const auto task_count = static_cast<size_t>(c.uncertain);
  const int64_t uncertain_kinds =
      large_pairs
          ? decode_pairs(
                pair_count, frame,
                [&](size_t i) {
                  return std::pair<uint64_t, uint8_t>{keys_host_.data()[i], status_host_.data()[i]};
                })
          : decode_pairs(pair_count, frame, [&](size_t i) {
              const uint64_t packed = host_pairs_[set].data()[i];
              return std::pair<uint64_t, uint8_t>{packed & ((uint64_t{1} << kStatusShift) - 1),
                                                  static_cast<uint8_t>(packed >> kStatusShift)};
            });
  decode_tasks(large_tasks ? uncertain_host_.data() : host_uncertain_[set].data(), task_count,
               frame);
  frame.filtered_tests = static_cast<int64_t>(c.misses + c.hits) +
                         static_cast<int64_t>(frame.pairs.size()) - uncertain_kinds;
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

namespace {

std::string runtime_error_text(cudaError_t status) {
  std::string text = cudaGetErrorName(status);
  text += " (";
  text += cudaGetErrorString(status);
  text += ")";
  return text;
}

std::string cuda_version_text(int version) {
  return std::to_string(version / 1000) + "." + std::to_string(version % 1000 / 10);
}

/// A kernel that does nothing, compiled like every other: whether the runtime finds code of
/// this build for a device.
__global__ void usability_probe_kernel() {}

}  // namespace

std::string cuda_runtime_problem() {
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  cudaGetLastError();
  if (status == cudaSuccess || status == cudaErrorNoDevice) return {};
  int driver = 0;
  if (cudaDriverGetVersion(&driver) != cudaSuccess || driver == 0) {
    cudaGetLastError();
    return {};  // no NVIDIA driver: a machine without a GPU
  }
  if (status == cudaErrorInsufficientDriver) {
    int runtime = 0;
    cudaRuntimeGetVersion(&runtime);
    return "the NVIDIA driver supports CUDA " + cuda_version_text(driver) +
           ", older than this build's CUDA runtime (" + cuda_version_text(runtime) +
           "): update the driver";
  }
  return "the CUDA runtime found no usable device: " + runtime_error_text(status);
}

std::string cuda_build_description() {
  return std::string("architectures ") + SNAG_CUDA_ARCHITECTURES_TEXT + "; CUDA runtime " +
         cuda_version_text(CUDART_VERSION) + ", linked statically";
}

std::string cuda_device_problem(int device) {
  const int count = cuda_device_count();
  if (device < 0 || device >= count)
    return "there is no CUDA device " + std::to_string(device) + " (" + std::to_string(count) +
           " here)";
  cudaDeviceProp prop{};
  if (const cudaError_t status = cudaGetDeviceProperties(&prop, device); status != cudaSuccess) {
    cudaGetLastError();
    return "CUDA device " + std::to_string(device) + ": " + runtime_error_text(status);
  }
  const std::string which = "CUDA device " + std::to_string(device) + " (" + prop.name +
                            ", compute capability " + std::to_string(prop.major) + "." +
                            std::to_string(prop.minor) + ")";
  // Creating the device's context fails for a device held by another process in exclusive
  // mode, or set to prohibited; finding the probe's code fails for a GPU the build has none
  // for (machine code for older architectures only runs on its own family, PTX only on its
  // architecture and newer).
  cudaError_t status = cudaSetDevice(device);
  if (status == cudaSuccess) status = cudaFree(nullptr);
  cudaFuncAttributes attributes{};
  if (status == cudaSuccess) status = cudaFuncGetAttributes(&attributes, usability_probe_kernel);
  if (status == cudaSuccess) return {};
  cudaGetLastError();
  if (status == cudaErrorNoKernelImageForDevice || status == cudaErrorInvalidDeviceFunction ||
      status == cudaErrorUnsupportedPtxVersion)
    return which + " cannot run this build's kernels, compiled for CUDA architectures " +
           SNAG_CUDA_ARCHITECTURES_TEXT +
           ": rebuild with -DSNAG_CUDA_ARCHITECTURES=" + std::to_string(prop.major) +
           std::to_string(prop.minor) + " (" + runtime_error_text(status) + ")";
  return which + " cannot be used: " + runtime_error_text(status);
}

std::unique_ptr<detect::Backend> make_cuda_backend(int device) {
  const int count = cuda_device_count();
  if (count == 0) throw InternalError("no CUDA device is usable here (no GPU, or no driver)");
  if (device < 0 || device >= count)
    throw InternalError("there is no CUDA device " + std::to_string(device) + " (" +
                        std::to_string(count) + " here, numbered from 0)");
  if (const std::string problem = cuda_device_problem(device); !problem.empty())
    throw InternalError(problem);
  return std::make_unique<CudaBackendImpl>(device);
}

}  // namespace snag::cuda
