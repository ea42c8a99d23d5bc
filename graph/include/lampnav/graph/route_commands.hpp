#pragma once
// Route commands, the words a person gives a robot (seed paper 2: "follow the corridor and turn
// right at the first corner"). Both ways: a planned route becomes commands, and text parses into
// commands with a small grammar:
//
//   follow corridor NAME | follow the corridor
//   turn (left|right) at the ORDINAL (corner|junction)
//   go through door NAME
//   enter (hall|room) NAME
//   stop at door NAME [(ORDINAL door on the (left|right))] | stop at the ORDINAL door on the SIDE
//   stop at PLACE NAME          (PLACE: corridor, junction, corner, end, hall, room)
//   go to NAME
//
// Commands are separated by ',', ';', '.', a new line, "and" or "then". ORDINAL is first..tenth,
// next (= first), or 1st, 2nd, 3rd, 4th... NAME runs to the end of the command; quote it ("Lab 3")
// when it holds a separator word or a parenthesis.

#include <string>
#include <vector>

#include "lampnav/core/error.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/graph/planner.hpp"

namespace lampnav::graph {

enum class CommandKind {
  follow_corridor,
  turn,
  go_through_door,
  enter,
  stop_at_node,
  stop_at_door,
  go_to
};
enum class TurnDirection { left, right };

struct RouteCommand {
  CommandKind kind = CommandKind::follow_corridor;
  std::string target;             // node or door name; empty for "follow the corridor" and
                                  // "stop at the second door on the left"
  Place place = Place::corridor;  // turn: corner/junction; enter: hall/room;
                                  // stop_at_node: the node's place
  TurnDirection direction = TurnDirection::left;  // turn
  int ordinal = 0;         // turn: the Nth place of that kind since the previous command;
                           // stop_at_door: the Nth door on `side` (0: not given)
  Side side = Side::left;  // stop_at_door, when ordinal > 0

  std::string text() const;
  friend bool operator==(const RouteCommand& a, const RouteCommand& b);
  friend bool operator!=(const RouteCommand& a, const RouteCommand& b) { return !(a == b); }
};

// "first", "second", ... "tenth", then "11th".
std::string ordinal_word(int n);
// "1st", "2nd", "3rd", "4th", ... "11th", "21st".
std::string ordinal_number(int n);

// Turn angles within this of straight ahead (rad) are not turns: the place is passed.
constexpr double kStraightTolerance = 35.0 * 3.14159265358979323846 / 180.0;

// The commands that drive a planned route. Turn directions come from the geometry of the way in
// and the way out; ordinals count the places of that kind passed since the previous command.
std::vector<RouteCommand> route_to_commands(const TopologicalMap& map, const Route& route);

// A sentence that does not fit the grammar: `column` (1-based) and `word` point at the culprit.
class CommandParseError : public InputError {
 public:
  CommandParseError(std::string source, std::string text, std::size_t column, std::string word,
                    std::string message);
  std::size_t column() const { return column_; }
  const std::string& word() const { return word_; }
  // The text with a caret line under the offending word.
  std::string pointer() const;

 private:
  std::string text_;
  std::size_t column_;
  std::string word_;
};

// Parses command text; throws CommandParseError. `source` names where the text came from.
std::vector<RouteCommand> parse_route_commands(const std::string& text,
                                               const std::string& source = "command");

// Checks parsed commands against a map: names must exist and be of the place the command says.
// Throws InputError naming the command (by number) and the name.
void check_commands(const TopologicalMap& map, const std::vector<RouteCommand>& commands,
                    const std::string& source = "command");

}  // namespace lampnav::graph
