#pragma once
// A stable sort by a small integer key (a pair's contact-graph level): the order std::stable_sort
// gives, found by counting when the keys span a range not much wider than the list. The level
// lists of the contact stages and of push-out are sorted this way on the recording thread before
// their tasks are shared, so that thread's time is the other's wait.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace monolith::solvers::contact {

// Sorts `items` by key(item) ascending, equal keys in their given order. Keys are ints.
template <class T, class Key>
void stableSortByKey(std::vector<T>& items, Key&& key) {
  const std::size_t n = items.size();
  if (n < 2) return;
  int lo = key(items[0]), hi = lo;
  bool sorted = true;
  for (std::size_t k = 1; k < n; ++k) {
    const int v = key(items[k]);
    sorted = sorted && key(items[k - 1]) <= v;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (sorted) return;
  const std::size_t range = static_cast<std::size_t>(hi) - static_cast<std::size_t>(lo) + 1;
  if (range > 4 * n + 64) {
    std::stable_sort(items.begin(), items.end(), [&](const T& x, const T& y) { return key(x) < key(y); });
    return;
  }
  thread_local std::vector<std::size_t> next;
  thread_local std::vector<T> out;
  next.assign(range + 1, 0);
  for (const T& item : items) ++next[static_cast<std::size_t>(key(item) - lo) + 1];
  for (std::size_t b = 0; b < range; ++b) next[b + 1] += next[b];
  out.resize(n);
  for (const T& item : items) out[next[static_cast<std::size_t>(key(item) - lo)]++] = item;
  items.swap(out);
}

}  // namespace monolith::solvers::contact
