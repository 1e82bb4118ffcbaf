#pragma once
// Parallel sweeps over [0, n) by fixed blocks: what they gather or sum is the same for any number of
// threads (each block in index order, the blocks joined in order), so runs stay reproducible.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace bodyfit {

inline constexpr int kSweepBlock = 8192;

/// The results of f(i) for i in [0, n) that f sets (f returns false for none), in index order.
template <class T, class F>
std::vector<T> collect(int n, F&& f) {
  const int blocks = (n + kSweepBlock - 1) / kSweepBlock;
  std::vector<std::vector<T>> parts(std::size_t(std::max(blocks, 0)));
  tbb::parallel_for(0, blocks, [&](int b) {
    T item;
    for (int i = b * kSweepBlock; i < std::min(n, (b + 1) * kSweepBlock); ++i)
      if (f(i, item)) parts[std::size_t(b)].push_back(item);
  });
  std::vector<T> all;
  std::size_t total = 0;
  for (const auto& p : parts) total += p.size();
  all.reserve(total);
  for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
  return all;
}

/// What f(i, out) appends to `out` for i in [0, n), in index order (into `all`, emptied first).
template <class T, class F>
void append_in_order(int n, std::vector<T>& all, F&& f) {
  all.clear();
  const int blocks = (n + kSweepBlock - 1) / kSweepBlock;
  if (blocks <= 1) {  // one block: no copy
    for (int i = 0; i < n; ++i) f(i, all);
    return;
  }
  std::vector<std::vector<T>> parts(static_cast<std::size_t>(blocks));
  tbb::parallel_for(0, blocks, [&](int b) {
    for (int i = b * kSweepBlock; i < std::min(n, (b + 1) * kSweepBlock); ++i) f(i, parts[std::size_t(b)]);
  });
  std::size_t total = 0;
  for (const auto& p : parts) total += p.size();
  all.reserve(total);
  for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
}

/// `add(i, partial)` for i in [0, n), each block into its own partial (a copy of `zero`), the
/// partials then folded in block order by `join(total, partial)`.
template <class T, class Add, class Join>
T reduce(int n, const T& zero, Add&& add, Join&& join) {
  const int blocks = (n + kSweepBlock - 1) / kSweepBlock;
  std::vector<T> parts(std::size_t(std::max(blocks, 0)), zero);
  tbb::parallel_for(0, blocks, [&](int b) {
    T& part = parts[std::size_t(b)];
    for (int i = b * kSweepBlock; i < std::min(n, (b + 1) * kSweepBlock); ++i) add(i, part);
  });
  T total = zero;
  for (const auto& p : parts) join(total, p);
  return total;
}

/// f(i) for i in [0, n), in parallel (f writes only what belongs to i).
template <class F>
void for_each_index(int n, F&& f) {
  tbb::parallel_for(0, (n + kSweepBlock - 1) / kSweepBlock, [&](int b) {
    for (int i = b * kSweepBlock; i < std::min(n, (b + 1) * kSweepBlock); ++i) f(i);
  });
}

/// term(i) for i in [0, n), computed in parallel, in a vector.
template <class Term>
std::vector<double> terms(int n, Term&& term) {
  std::vector<double> values(std::size_t(std::max(n, 0)));
  for_each_index(n, [&](int i) { values[std::size_t(i)] = term(i); });
  return values;
}

/// Σ term(i) over [0, n): the terms computed in parallel, added in index order as a serial loop adds
/// them (the same bits: a sum a model reads, such as the mean edge length, steers discrete choices).
template <class Term>
double sum_in_order(int n, Term&& term) {
  double sum = 0;
  for (double value : terms(n, term)) sum += value;
  return sum;
}

}  // namespace bodyfit
