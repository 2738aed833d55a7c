#include "decimate/collapse_snapshots.hpp"

#include <algorithm>
#include <array>

#include "topstoc/core/digest.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

namespace {

template <class T>
void add(std::vector<uint64_t>& key, const T* data, size_t count) {
  const std::array<uint64_t, 2> d = content_digest(data, count * sizeof(T));
  key.insert(key.end(), {uint64_t(count), d[0], d[1]});
}

template <class T>
void add(std::vector<uint64_t>& key, const std::vector<T>& values) {
  add(key, values.data(), values.size());
}

}  // namespace

std::vector<uint64_t> start_key(const CollapseSetup& s, const std::vector<int32_t>& triangles,
                                const std::vector<int32_t>& corner_source) {
  std::vector<uint64_t> key;
  const size_t n = s.weight.size();
  key.push_back(uint64_t(s.quadrics.channels()));
  add(key, n > 0 ? s.quadrics.at(0) : nullptr, n * size_t(s.quadrics.stride()));
  add(key, s.positions);
  add(key, s.world);
  add(key, s.center, 3);
  add(key, &s.extent, 1);
  add(key, s.weight);
  add(key, s.locked);
  add(key, s.curve);
  add(key, s.curve_size);
  add(key, s.curve_closed);
  add(key, s.curve_locked_ends);
  add(key, s.dead_end);
  add(key, s.on_boundary);
  add(key, s.corner_sector);
  add(key, s.bin);
  key.push_back(s.optimal_placement);
  add(key, s.input_floor2);
  key.push_back(s.input_floor_flat_only);
  add(key, s.curve_order);
  add(key, s.curve_offsets);
  add(key, s.curve_slot);
  add(key, s.curve_points);
  add(key, &s.span_weight, 1);
  add(key, triangles);
  add(key, corner_source);
  return key;
}

std::vector<uint64_t> input_surface_key(const Mesh& mesh, const Collapser& collapser, int64_t step) {
  // a Mesh never changes: its serial names its positions and triangles
  std::vector<uint64_t> key{mesh.serial(), uint64_t(step)};
  const double corners[2][3] = {{0, 0, 0}, {1, 1, 1}};
  double normalised[2][3];
  for (int i = 0; i < 2; ++i) collapser.normalise(corners[i], normalised[i]);
  add(key, &normalised[0][0], 6);
  return key;
}

std::shared_ptr<const CollapseSnapshots::Entry> snapshot(std::vector<uint64_t> start, int32_t run_vertices,
                                                         int32_t collapses, const Collapser& collapser) {
  auto entry = std::make_shared<CollapseSnapshots::Entry>();
  entry->start = std::move(start);
  entry->run_vertices = run_vertices;
  entry->collapses = collapses;
  entry->triangles = collapser.triangles();
  entry->corner_source = collapser.corner_source();
  entry->state = std::make_unique<Collapser>(collapser);
  entry->state->use_arrays(entry->triangles, entry->corner_source);
  return entry;
}

std::unique_ptr<Collapser> resumed(const CollapseSnapshots::Entry& entry, std::vector<int32_t>& triangles,
                                   std::vector<int32_t>& corner_source, std::vector<int32_t> quota) {
  triangles = entry.triangles;
  corner_source = entry.corner_source;
  auto out = std::make_unique<Collapser>(*entry.state);
  out->use_arrays(triangles, corner_source);
  out->set_quota(std::move(quota));
  out->fit_threads();  // the state may come from a call on a team of another size
  return out;
}

CollapseSnapshots::CollapseSnapshots(size_t capacity) : capacity_(capacity) {}
CollapseSnapshots::~CollapseSnapshots() = default;

std::shared_ptr<const CollapseSnapshots::Entry> CollapseSnapshots::find(const std::vector<uint64_t>& start,
                                                                        int32_t vertices) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::shared_ptr<const Entry> best;
  for (const auto& e : entries_)
    if (e->start == start && e->run_vertices >= vertices && (!best || e->run_vertices < best->run_vertices))
      best = e;
  resumed_ += best != nullptr;
  return best;
}

bool CollapseSnapshots::keeps_plain_run(bool warm_up) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool keeps = warm_up || plain_runs_ > 0;
  ++plain_runs_;
  return keeps;
}

void CollapseSnapshots::keep(std::shared_ptr<const Entry> entry) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto e = entries_.begin(); e != entries_.end(); ++e)
    if ((*e)->start == entry->start && (*e)->run_vertices == entry->run_vertices) {
      entries_.erase(e);  // the same state again: kept once, as the most recent
      break;
    }
  entries_.push_back(std::move(entry));
  if (entries_.size() <= capacity_) return;
  // The oldest goes, unless it is the state for the highest target, which serves every lower
  // one (a drag back down): then the next oldest.
  size_t highest = 0;
  for (size_t i = 1; i < entries_.size(); ++i)
    if (entries_[i]->run_vertices > entries_[highest]->run_vertices) highest = i;
  entries_.erase(entries_.begin() + (highest == 0 && capacity_ > 1 ? 1 : 0));
}

std::shared_ptr<const Surface> CollapseSnapshots::input_surface(
    const std::vector<uint64_t>& key, const std::function<std::shared_ptr<const Surface>()>& make) {
  std::lock_guard<std::mutex> lock(mutex_);  // held while one is made: a second caller takes it
  for (auto kept = surfaces_.begin(); kept != surfaces_.end(); ++kept)
    if (kept->first == key) {
      std::rotate(kept, kept + 1, surfaces_.end());  // the most recently used last
      return surfaces_.back().second;
    }
  if (surfaces_.size() >= kSurfaces) surfaces_.erase(surfaces_.begin());  // freed before the new one is made
  surfaces_.emplace_back(key, make());
  ++surfaces_made_;
  return surfaces_.back().second;
}

void CollapseSnapshots::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.clear();
  surfaces_.clear();
}

size_t CollapseSnapshots::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

size_t CollapseSnapshots::surfaces() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return surfaces_.size();
}

size_t CollapseSnapshots::resumed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return resumed_;
}

size_t CollapseSnapshots::surfaces_made() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return surfaces_made_;
}

}  // namespace topstoc
