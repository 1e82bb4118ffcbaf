// A pass's relocations on every thread, with the result of the loop over the work list in its
// order: each vertex sees the new places of the vertices listed before it and the old places of
// those after (Remesher::relocate_in_waves).
//
// A relocation reads the places of its vertex's ring and of the far corners of the triangles across
// the ring's sides (and the ring's hint faces), and writes only its own vertex's place, hint face
// and normal (Remesher::relocate). So each listed vertex has "reads": the listed-before vertices
// among those, gathered in parallel; and a wave, one after the latest wave among its reads, so that
// no vertex of a wave reads one of the same wave. The threads take the list ordered by wave in
// chunks, and a vertex waits until its reads are done: they are all earlier in that order, so the
// earliest vertex in progress never waits.
#include "remesher.hpp"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <span>
#include <thread>
#include <vector>

namespace bodyfit::remesh_detail {
namespace {

/// Each listed vertex's reads (indices in the list), kept by blocks of the list so that the blocks
/// are gathered in parallel.
struct ListedReads {
  static constexpr std::size_t kBlock = 2048;
  std::vector<std::vector<int>> blocks;
  std::vector<std::uint32_t> end;  ///< where item i's reads end in its block
  explicit ListedReads(std::size_t count) : blocks((count + kBlock - 1) / kBlock), end(count) {}
  std::span<const int> of(std::size_t i) const {
    const std::size_t begin = i % kBlock == 0 ? 0 : end[i - 1];
    return {blocks[i / kBlock].data() + begin, end[i] - begin};
  }
};

/// The list's indices ordered by wave, list order within a wave (a counting sort): an item's wave is
/// one after the latest wave among its reads. `live(i)`: whether item i is run at all.
template <class Live>
std::vector<int> order_by_wave(const ListedReads& reads, std::size_t count, Live&& live) {
  std::vector<int> wave(count, -1);
  int waves = 0;
  for (std::size_t i = 0; i < count; ++i) {
    if (!live(i)) continue;
    int w = 0;
    for (int j : reads.of(i)) w = std::max(w, wave[std::size_t(j)] + 1);
    wave[i] = w;
    waves = std::max(waves, w + 1);
  }
  std::vector<int> order, next(std::size_t(waves) + 1, 0);
  for (int w : wave)
    if (w >= 0) ++next[std::size_t(w) + 1];
  for (int w = 0; w < waves; ++w) next[std::size_t(w) + 1] += next[std::size_t(w)];
  order.resize(std::size_t(next[std::size_t(waves)]));
  for (std::size_t i = 0; i < count; ++i)
    if (wave[i] >= 0) order[std::size_t(next[std::size_t(wave[i])]++)] = int(i);
  return order;
}

/// run(i) for every item of `order` on `threads` threads, each once its reads have run: the threads
/// take `order` in chunks, and an item waits until its reads are done. Its reads come before it in
/// `order`, so the earliest item in progress never waits. Each thread's chunks run isolated: a
/// parallel loop inside run(i) (a search structure built on first use) waits by running tasks, and
/// must not run another thread's share of the chunks there, which could wait for the item below it
/// on the same thread. An exception stops the others (rather than leave them waiting for the item
/// that threw) and is rethrown.
template <class Run>
void run_after_reads(const std::vector<int>& order, const ListedReads& reads, std::size_t count, int threads,
                     Run&& run) {
  const int total = int(order.size());
  std::unique_ptr<std::atomic<bool>[]> done(new std::atomic<bool>[count]);
  for (std::size_t i = 0; i < count; ++i) done[i].store(false, std::memory_order_relaxed);
  std::atomic<int> taken{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  auto take_chunks = [&] {
    constexpr int kChunk = 8;  // items per take: a relocation is a microsecond or so
    tbb::this_task_arena::isolate([&] {
      try {
        for (int begin; (begin = taken.fetch_add(kChunk, std::memory_order_relaxed)) < total;)
          for (int k = begin; k < std::min(begin + kChunk, total); ++k) {
            const auto i = std::size_t(order[std::size_t(k)]);
            for (int j : reads.of(i))
              while (!done[std::size_t(j)].load(std::memory_order_acquire)) {
                if (failed.load(std::memory_order_relaxed)) return;
                std::this_thread::yield();
              }
            run(i);
            done[i].store(true, std::memory_order_release);
          }
      } catch (...) {
        if (!failed.exchange(true)) error = std::current_exception();
      }
    });
  };
  tbb::task_group helpers;
  for (int t = 1; t < threads; ++t) helpers.run(take_chunks);
  take_chunks();
  helpers.wait();
  if (error) std::rethrow_exception(error);
}

}  // namespace

void Remesher::relocate_in_waves(std::size_t count, std::vector<double>& moved) {
  moved.assign(count, -1.0);
  // A short queue runs the loop: the runs' remeshes, whose passes queue a few hundred vertices,
  // were no faster in waves from 64 vertices than from 512 or never.
  constexpr std::size_t kWavesFrom = 512;
  const int threads = int(std::min(std::size_t(tbb::this_task_arena::max_concurrency()),
                                   tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
  if (count < kWavesFrom || threads < 2) {
    for (std::size_t i = 0; i < count; ++i)
      if (!m_.status(work_[i]).deleted()) moved[i] = relocate(work_[i]);
    return;
  }
  curves_.prepare();  // its search tree, before the threads query it

  const auto live = [&](std::size_t i) { return !m_.status(work_[i]).deleted(); };
  auto each_listed = [&](auto&& body) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, ListedReads::kBlock), [&](const auto& range) {
      for (std::size_t i = range.begin(); i < range.end(); ++i)
        if (live(i)) body(i, work_[i]);
    });
  };
  // Each live vertex's reads, found through listed_ (each vertex's place in the list, −1 between passes).
  if (listed_.size() < m_.n_vertices()) listed_.resize(m_.n_vertices(), -1);
  each_listed([&](std::size_t i, VertexHandle v) { listed_[std::size_t(v.idx())] = int(i); });
  ListedReads reads(count);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, reads.blocks.size()), [&](const auto& range) {
    for (std::size_t b = range.begin(); b < range.end(); ++b) {
      std::vector<int>& block = reads.blocks[b];
      block.reserve(8 * ListedReads::kBlock);
      for (std::size_t i = b * ListedReads::kBlock; i < std::min(count, (b + 1) * ListedReads::kBlock); ++i) {
        const VertexHandle v = work_[i];
        auto read = [&](VertexHandle u) {
          const int j = listed_[std::size_t(u.idx())];
          if (j >= 0 && std::size_t(j) < i) block.push_back(j);
        };
        if (live(i))
          for (auto h : m_.voh_range(v)) {
            read(m_.to_vertex_handle(h));
            if (m_.is_boundary(h)) continue;
            const auto outer = m_.opposite_halfedge_handle(m_.next_halfedge_handle(h));
            if (!m_.is_boundary(outer)) read(m_.to_vertex_handle(m_.next_halfedge_handle(outer)));
          }
        reads.end[i] = std::uint32_t(block.size());
      }
    }
  });
  each_listed([&](std::size_t, VertexHandle v) { listed_[std::size_t(v.idx())] = -1; });

  run_after_reads(order_by_wave(reads, count, live), reads, count, threads,
                  [&](std::size_t i) { moved[i] = relocate(work_[i]); });
}

}  // namespace bodyfit::remesh_detail
