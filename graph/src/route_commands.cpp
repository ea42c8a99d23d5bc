#include "lampnav/graph/route_commands.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "lampnav/graph/corridor_geometry.hpp"
#include "lampnav/graph/geometry.hpp"

namespace lampnav::graph {

using Eigen::Vector2d;

namespace {

const char* const kOrdinals[] = {"first", "second",  "third",  "fourth", "fifth",
                                 "sixth", "seventh", "eighth", "ninth",  "tenth"};

bool needs_quotes(const std::string& name) {
  if (name.find_first_of(",;()\"\n\t\r") != std::string::npos) return true;
  // Unquoted, a name is words one space apart.
  if (name.empty() || name.front() == ' ' || name.back() == ' ' ||
      name.find("  ") != std::string::npos)
    return true;
  if (name.find(". ") != std::string::npos || (!name.empty() && name.back() == '.')) return true;
  std::string padded = " " + name + " ";
  for (auto& ch : padded) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return padded.find(" and ") != std::string::npos || padded.find(" then ") != std::string::npos;
}

std::string quoted(const std::string& name) {
  return needs_quotes(name) ? "\"" + name + "\"" : name;
}

}  // namespace

std::string ordinal_word(int n) {
  if (n >= 1 && n <= 10) return kOrdinals[n - 1];
  return ordinal_number(n);
}

std::string ordinal_number(int n) {
  const int mod100 = n % 100, mod10 = n % 10;
  const char* suffix = (mod100 >= 11 && mod100 <= 13) ? "th"
                       : mod10 == 1                   ? "st"
                       : mod10 == 2                   ? "nd"
                       : mod10 == 3                   ? "rd"
                                                      : "th";
  return std::to_string(n) + suffix;  // the parser accepts the same suffixes
}

std::string RouteCommand::text() const {
  switch (kind) {
    case CommandKind::follow_corridor:
      return target.empty() ? "follow the corridor" : "follow corridor " + quoted(target);
    case CommandKind::turn:
      return std::string("turn ") + (direction == TurnDirection::left ? "left" : "right") +
             " at the " + ordinal_word(ordinal) + " " + to_string(place);
    case CommandKind::go_through_door:
      return "go through door " + quoted(target);
    case CommandKind::enter:
      return std::string("enter ") + to_string(place) + " " + quoted(target);
    case CommandKind::stop_at_node:
      return std::string("stop at ") + to_string(place) + " " + quoted(target);
    case CommandKind::stop_at_door: {
      const std::string which =
          ordinal > 0 ? ordinal_word(ordinal) + " door on the " + to_string(side) : "";
      if (target.empty()) return "stop at the " + which;
      return "stop at door " + quoted(target) + (which.empty() ? "" : " (" + which + ")");
    }
    case CommandKind::go_to:
      return "go to " + quoted(target);
  }
  return {};
}

bool operator==(const RouteCommand& a, const RouteCommand& b) {
  if (a.kind != b.kind || a.target != b.target) return false;
  switch (a.kind) {
    case CommandKind::turn:
      return a.direction == b.direction && a.ordinal == b.ordinal && a.place == b.place;
    case CommandKind::enter:
    case CommandKind::stop_at_node:
      return a.place == b.place;
    case CommandKind::stop_at_door:
      return a.ordinal == b.ordinal && (a.ordinal == 0 || a.side == b.side);
    default:
      return true;
  }
}

// ---------------------------------------------------------------------------------------------
// Planned route -> commands.

namespace {

Side flipped(Side s) { return s == Side::left ? Side::right : Side::left; }

struct Passed {
  int junction = 0, corner = 0;
  int left_doors = 0, right_doors = 0;
  int& places(Place p) { return p == Place::junction ? junction : corner; }
  int& doors(Side s) { return s == Side::left ? left_doors : right_doors; }
};

}  // namespace

std::vector<RouteCommand> route_to_commands(const TopologicalMap& map, const Route& route) {
  std::vector<RouteCommand> cmds;
  Passed passed;
  bool continuing = false;  // the previous place was passed straight: keep following
  int door_ordinal = 0;     // of the door the current corridor leads to, on `door_side`
  Side door_side = Side::left;
  auto emit = [&](RouteCommand c) {
    cmds.push_back(std::move(c));
    passed = Passed{};
  };
  const std::size_t k = route.nodes.size();
  for (std::size_t i = 0; i < k; ++i) {
    const Node& n = map.node(route.nodes[i]);
    const Node* prev = i > 0 ? &map.node(route.nodes[i - 1]) : nullptr;
    const Node* next = i + 1 < k ? &map.node(route.nodes[i + 1]) : nullptr;
    const bool last = next == nullptr;
    RouteCommand c;
    c.target = n.name;
    c.place = n.place;
    switch (n.place) {
      case Place::corridor: {
        if (!continuing) {
          c.kind = CommandKind::follow_corridor;
          emit(c);
        }
        continuing = false;
        if (!n.axis) break;
        const double s_in = entry_point(n, prev);
        const double s_out = entry_point(n, next);
        const bool forward = s_out >= s_in;
        const Door* target = next && next->place == Place::door ? n.find_door(next->name) : nullptr;
        for (const Door& d : n.doors) {
          if (&d == target) continue;
          const bool between =
              forward ? (d.at > s_in && d.at < s_out) : (d.at < s_in && d.at > s_out);
          if (between) ++passed.doors(forward ? d.side : flipped(d.side));
        }
        if (target) {
          door_side = forward ? target->side : flipped(target->side);
          door_ordinal = passed.doors(door_side) + 1;
        }
        if (last) {
          c.kind = CommandKind::stop_at_node;
          emit(c);
        }
        break;
      }
      case Place::junction:
      case Place::corner: {
        if (!prev) break;
        if (last) {
          c.kind = CommandKind::stop_at_node;
          emit(c);
          break;
        }
        const Vector2d in = n.point - far_anchor(*prev, n.point);
        const Vector2d out = far_anchor(*next, n.point) - n.point;
        const double angle = signed_angle(in, out);
        ++passed.places(n.place);
        if (std::fabs(angle) <= kStraightTolerance) {
          continuing = next->place == Place::corridor;
        } else {
          c.kind = CommandKind::turn;
          c.target.clear();  // a turn names the kind of place and its ordinal, not the place
          c.direction = angle > 0 ? TurnDirection::left : TurnDirection::right;
          c.ordinal = passed.places(n.place);
          emit(c);
          continuing = false;
        }
        break;
      }
      case Place::door: {
        if (last) {
          if (prev && prev->place == Place::corridor && prev->find_door(n.name)) {
            c.kind = CommandKind::stop_at_door;
            c.ordinal = door_ordinal;
            c.side = door_side;
          } else {
            c.kind = CommandKind::stop_at_node;
          }
          emit(c);
        } else if (prev) {
          c.kind = CommandKind::go_through_door;
          emit(c);
        }
        continuing = false;
        break;
      }
      case Place::hall:
      case Place::room:
        if (prev) {
          c.kind = CommandKind::enter;
          emit(c);
        }
        continuing = false;
        break;
      case Place::end:
        if (last && prev) {
          c.kind = CommandKind::stop_at_node;
          emit(c);
        }
        continuing = false;
        break;
      case Place::waypoint:  // a Nav2 graph: no places to speak of, each waypoint by name
        if (prev) {
          c.kind = CommandKind::go_to;
          emit(c);
        }
        continuing = false;
        break;
    }
  }
  return cmds;
}

}  // namespace lampnav::graph
