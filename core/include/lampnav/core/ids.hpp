#pragma once
// Identifiers as small value types, so a node id cannot be passed where a lamp id is meant.

#include <cstdint>
#include <functional>
#include <ostream>
#include <string>

namespace lampnav {

template <class Tag, class T>
struct Id {
  T value{};

  Id() = default;
  explicit Id(T v) : value(std::move(v)) {}

  friend bool operator==(const Id& a, const Id& b) { return a.value == b.value; }
  friend bool operator!=(const Id& a, const Id& b) { return !(a == b); }
  friend bool operator<(const Id& a, const Id& b) { return a.value < b.value; }
  friend std::ostream& operator<<(std::ostream& os, const Id& id) { return os << id.value; }
};

struct NodeTag {};
struct EdgeTag {};
struct LampTag {};

// Map feature ids are integers unique among all features (map-format.md).
using NodeId = Id<NodeTag, std::int64_t>;
using EdgeId = Id<EdgeTag, std::int64_t>;
// Lamp ids are strings unique in the map ("C2-L1").
using LampId = Id<LampTag, std::string>;

}  // namespace lampnav

template <class Tag, class T>
struct std::hash<lampnav::Id<Tag, T>> {
  std::size_t operator()(const lampnav::Id<Tag, T>& id) const noexcept {
    return std::hash<T>{}(id.value);
  }
};
