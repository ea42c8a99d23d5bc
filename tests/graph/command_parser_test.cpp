#include "lampnav/graph/route_commands.hpp"
#include "lampnav_test.hpp"
#include "map_sketch.hpp"

namespace lampnav::graph {
namespace {

using ::testing::HasSubstr;

std::vector<std::string> texts(const std::vector<RouteCommand>& cmds) {
  std::vector<std::string> out;
  for (const auto& c : cmds) out.push_back(c.text());
  return out;
}

TEST(CommandParser, PaperSentence) {
  const auto cmds = parse_route_commands("follow the corridor and turn right at the first corner");
  ASSERT_EQ(cmds.size(), 2u);
  EXPECT_EQ(cmds[0].kind, CommandKind::follow_corridor);
  EXPECT_TRUE(cmds[0].target.empty());
  EXPECT_EQ(cmds[1].kind, CommandKind::turn);
  EXPECT_EQ(cmds[1].direction, TurnDirection::right);
  EXPECT_EQ(cmds[1].ordinal, 1);
  EXPECT_EQ(cmds[1].place, Place::corner);
}

TEST(CommandParser, EverySentenceOfTheGrammar) {
  const auto cmds = parse_route_commands(
      "Follow corridor C1, turn left at the 2nd junction; go through door D4 then enter hall E.\n"
      "stop at door Lab 3 (second door on the left), stop at the third door on the right, "
      "stop at end E2, go to Kitchen, enter room \"Tea and Biscuits\", turn right at the next "
      "corner");
  EXPECT_EQ(texts(cmds),
            (std::vector<std::string>{
                "follow corridor C1", "turn left at the second junction", "go through door D4",
                "enter hall E", "stop at door Lab 3 (second door on the left)",
                "stop at the third door on the right", "stop at end E2", "go to Kitchen",
                "enter room \"Tea and Biscuits\"", "turn right at the first corner"}));
  EXPECT_EQ(cmds[4].target, "Lab 3");
  EXPECT_EQ(cmds[4].ordinal, 2);
  EXPECT_EQ(cmds[4].side, Side::left);
  EXPECT_EQ(cmds[8].target, "Tea and Biscuits");
}

TEST(CommandParser, NumericOrdinals) {
  EXPECT_EQ(parse_route_commands("turn left at the 12th junction")[0].ordinal, 12);
  EXPECT_EQ(parse_route_commands("turn left at the 21st junction")[0].ordinal, 21);
  EXPECT_EQ(parse_route_commands("turn left at the 3rd corner")[0].ordinal, 3);
}

struct BadSentence {
  const char* name;
  const char* text;
  std::size_t column;
  const char* word;
  const char* message;
};

class BadSentenceTest : public ::testing::TestWithParam<BadSentence> {};

TEST_P(BadSentenceTest, PointsAtTheWordThatDoesNotFit) {
  const BadSentence& b = GetParam();
  try {
    parse_route_commands(b.text, "route text");
    FAIL() << "parsed: " << b.text;
  } catch (const CommandParseError& e) {
    EXPECT_EQ(e.column(), b.column) << e.what();
    EXPECT_EQ(e.word(), b.word) << e.what();
    EXPECT_THAT(e.message(), HasSubstr(b.message));
    EXPECT_THAT(std::string(e.what()), HasSubstr("route text: column"));
    EXPECT_THAT(e.pointer(), HasSubstr("^"));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Refusals, BadSentenceTest,
    ::testing::Values(
        BadSentence{"bad_direction", "turn lft at the first corner", 6, "lft",
                    "\"left\" or \"right\""},
        BadSentence{"bad_ordinal", "turn left at the frist corner", 18, "frist", "ordinal"},
        BadSentence{"wrong_suffix", "turn left at the 2th corner", 18, "2th", "ordinal"},
        BadSentence{"bad_place", "turn left at the first door", 24, "door",
                    "\"corner\" or \"junction\""},
        BadSentence{"unknown_verb", "follow corridor C1, jump over the wall", 21, "jump",
                    "\"follow\""},
        BadSentence{"missing_name", "follow corridor", 16, "", "corridor name"},
        BadSentence{"missing_name_before_and", "go through door and enter hall E", 17, "and",
                    "door name"},
        BadSentence{"unclosed_paren", "stop at door D3 (second door on the left", 41, "", "')'"},
        BadSentence{"bad_side", "stop at the second door on the top", 32, "top",
                    "\"left\" or \"right\""},
        BadSentence{"trailing_words", "turn left at the first corner please", 31, "please",
                    "end of the command"},
        BadSentence{"unterminated_quote", "go to \"Lab 3", 7, "\"Lab 3", "unterminated"},
        BadSentence{"empty", "  ,  ", 6, "", "no command"}),
    [](const auto& p) { return std::string(p.param.name); });

TEST(CheckCommands, NamesMustExistWithTheRightPlace) {
  test::MapSketch s;
  s.corridor("C1", {0, 0}, {10, 0}, {{"Lab 3", Side::left, 4.0}})
      .place("K", Place::corner, {11, 0})
      .place("Hall", Place::hall, {11, 6}, 8);
  EXPECT_NO_THROW(
      check_commands(s.map(), parse_route_commands("follow corridor C1, stop at door Lab 3")));
  try {
    check_commands(s.map(), parse_route_commands("follow corridor C1, enter hall C1"), "cmd.txt");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().place, "command 2 (enter hall C1)");
    EXPECT_THAT(e.message(), HasSubstr("is a corridor, not a hall"));
  }
  EXPECT_THROW(check_commands(s.map(), parse_route_commands("go to Nowhere")), InputError);
  EXPECT_THROW(check_commands(s.map(), parse_route_commands("stop at door Lab 9")), InputError);
}

// Found by the route-command fuzzer: a quoted name holding a tab and a NUL was taken, and written
// back it read as another command. Control characters are refused, naming where.
TEST(CommandParser, ControlCharactersAreRefusedWhereTheyAre) {
  try {
    parse_route_commands(std::string("stop at door \"La\t\0b 6\"", 23));
    FAIL() << "a NUL was read";
  } catch (const CommandParseError& e) {
    EXPECT_EQ(e.column(), 18u);
    EXPECT_THAT(e.what(), ::testing::HasSubstr("control character 0x00"));
  }
  EXPECT_THROW(parse_route_commands("stop at door \"Lab\t3\""), CommandParseError);
  EXPECT_THROW(parse_route_commands("go to J2\x1b[2J"), CommandParseError);
  EXPECT_NO_THROW(parse_route_commands("go to J2\r\nstop at end E1\t"));
}

}  // namespace
}  // namespace lampnav::graph
