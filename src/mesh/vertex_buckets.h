// Grouping a mesh's items (triangles, half-edges) by a vertex id in linear time.
#pragma once

#include <cstddef>
#include <vector>

namespace amc {

// Groups items by a vertex id with a counting sort (O(n), no comparison sort over the whole
// mesh); `bucket_of(i)` gives the vertex of item i, below vertex_count. Items keep their order
// within a bucket. Returns the start of every bucket: bucket v is [start[v], start[v + 1]).
template <typename Entry, typename BucketOf, typename MakeEntry>
std::vector<std::size_t> bucket_by_vertex(std::size_t vertex_count, std::size_t item_count,
                                          BucketOf bucket_of, MakeEntry make_entry,
                                          std::vector<Entry>& entries) {
    std::vector<std::size_t> start(vertex_count + 2, 0);
    for (std::size_t i = 0; i < item_count; ++i) ++start[bucket_of(i) + 2];
    for (std::size_t v = 2; v < start.size(); ++v) start[v] += start[v - 1];
    entries.resize(item_count);
    for (std::size_t i = 0; i < item_count; ++i) entries[start[bucket_of(i) + 1]++] = make_entry(i);
    start.pop_back();
    return start;
}

}  // namespace amc
