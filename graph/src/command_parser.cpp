// Text -> route commands: a small recursive-descent parser over words, with errors that point at
// the word that does not fit.

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <optional>

#include "lampnav/graph/route_commands.hpp"

namespace lampnav::graph {

CommandParseError::CommandParseError(std::string source, std::string text, std::size_t column,
                                     std::string word, std::string message)
    : InputError({std::move(source), "column " + std::to_string(column),
                  word.empty() ? "" : "'" + word + "'"},
                 std::move(message)),
      text_(std::move(text)),
      column_(column),
      word_(std::move(word)) {}

std::string CommandParseError::pointer() const {
  std::string line = text_;
  std::replace(line.begin(), line.end(), '\n', ' ');
  std::string caret(column_ > 0 ? column_ - 1 : 0, ' ');
  caret += std::string(std::max<std::size_t>(1, word_.size()), '^');
  return line + "\n" + caret;
}

namespace {

enum class Tok { word, quoted, open, close, separator };

struct Token {
  Tok kind;
  std::string text;    // as written (quoted: without the quotes)
  std::string lower;   // lower-case, for keywords
  std::size_t column;  // 1-based
};

std::string numeric_suffix(int n) {
  const int mod100 = n % 100, mod10 = n % 10;
  if (mod100 >= 11 && mod100 <= 13) return "th";
  return mod10 == 1 ? "st" : mod10 == 2 ? "nd" : mod10 == 3 ? "rd" : "th";
}

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

class Parser {
 public:
  Parser(const std::string& text, std::string source) : text_(text), source_(std::move(source)) {
    tokenize();
  }

  std::vector<RouteCommand> parse() {
    std::vector<RouteCommand> out;
    skip_separators();
    while (pos_ < toks_.size()) {
      out.push_back(command());
      if (pos_ < toks_.size()) {
        if (!is_separator(toks_[pos_]))
          fail(toks_[pos_],
               "expected the end of the command, or ',' / 'and' / 'then' before the next one");
        skip_separators();
      }
    }
    if (out.empty()) fail_at_end("no command given");
    return out;
  }

 private:
  [[noreturn]] void fail(const Token& t, const std::string& message) const {
    const std::string word = t.kind == Tok::quoted ? "\"" + t.text + "\"" : t.text;
    throw CommandParseError(source_, text_, t.column, word, message);
  }
  [[noreturn]] void fail_at_end(const std::string& message) const {
    throw CommandParseError(source_, text_, text_.size() + 1, "",
                            message + " (the text ends here)");
  }
  [[noreturn]] void fail_here(const std::string& message) const {
    if (pos_ < toks_.size() && !is_separator(toks_[pos_])) fail(toks_[pos_], message);
    if (pos_ < toks_.size()) fail(toks_[pos_], message + " (the command ends here)");
    fail_at_end(message);
  }

  static bool is_separator(const Token& t) {
    return t.kind == Tok::separator ||
           (t.kind == Tok::word && (t.lower == "and" || t.lower == "then"));
  }
  void skip_separators() {
    while (pos_ < toks_.size() && is_separator(toks_[pos_])) ++pos_;
  }
  const Token* peek() const {
    return pos_ < toks_.size() && !is_separator(toks_[pos_]) ? &toks_[pos_] : nullptr;
  }
  bool accept(const char* word) {
    const Token* t = peek();
    if (t && t->kind == Tok::word && t->lower == word) {
      ++pos_;
      return true;
    }
    return false;
  }
  void expect(const char* word) {
    if (!accept(word)) fail_here(std::string("expected \"") + word + "\"");
  }
  // One of `words`; returns its index.
  std::size_t expect_one(std::initializer_list<const char*> words) {
    const Token* t = peek();
    std::size_t i = 0;
    for (const char* w : words) {
      if (t && t->kind == Tok::word && t->lower == w) {
        ++pos_;
        return i;
      }
      ++i;
    }
    std::string list;
    i = 0;
    for (const char* w : words) {
      list +=
          (i == 0 ? "" : (i + 1 == words.size() ? " or " : ", ")) + std::string("\"") + w + "\"";
      ++i;
    }
    fail_here("expected " + list);
  }

  int ordinal() {
    const Token* t = peek();
    if (t && t->kind == Tok::word) {
      if (t->lower == "next") {
        ++pos_;
        return 1;
      }
      for (int i = 0; i < 10; ++i) {
        if (t->lower == kWords[i]) {
          ++pos_;
          return i + 1;
        }
      }
      // 1st, 2nd, 3rd, 4th, ... 21st
      std::size_t digits = 0;
      while (digits < t->lower.size() &&
             std::isdigit(static_cast<unsigned char>(t->lower[digits]))) {
        ++digits;
      }
      if (digits > 0 && digits <= 4 && t->lower.size() == digits + 2) {
        const int n = std::stoi(t->lower.substr(0, digits));
        if (n > 0 && t->lower.substr(digits) == numeric_suffix(n)) {
          ++pos_;
          return n;
        }
      }
    }
    fail_here("expected an ordinal (first, second, ... or 1st, 2nd, ...)");
  }

  // A name: one quoted string, or the words up to the end of the command or a '('.
  std::string name(const char* what) {
    const Token* t = peek();
    if (!t || t->kind == Tok::open || t->kind == Tok::close)
      fail_here(std::string("expected ") + what);
    if (t->kind == Tok::quoted) {
      ++pos_;
      return t->text;
    }
    std::string n;
    while ((t = peek()) && t->kind == Tok::word) {
      n += (n.empty() ? "" : " ") + t->text;
      ++pos_;
    }
    return n;
  }

  // "ORDINAL door on the SIDE"
  void which_door(RouteCommand& c) {
    c.ordinal = ordinal();
    expect("door");
    expect("on");
    expect("the");
    c.side = expect_one({"left", "right"}) == 0 ? Side::left : Side::right;
  }

  RouteCommand command() {
    RouteCommand c;
    switch (expect_one({"follow", "turn", "go", "enter", "stop"})) {
      case 0:  // follow
        c.kind = CommandKind::follow_corridor;
        if (accept("the")) {
          expect("corridor");
        } else {
          expect("corridor");
          c.target = name("a corridor name");
        }
        break;
      case 1:  // turn
        c.kind = CommandKind::turn;
        c.direction =
            expect_one({"left", "right"}) == 0 ? TurnDirection::left : TurnDirection::right;
        expect("at");
        expect("the");
        c.ordinal = ordinal();
        c.place = expect_one({"corner", "junction"}) == 0 ? Place::corner : Place::junction;
        break;
      case 2:  // go through door NAME | go to NAME
        if (expect_one({"through", "to"}) == 0) {
          c.kind = CommandKind::go_through_door;
          expect("door");
          c.target = name("a door name");
        } else {
          c.kind = CommandKind::go_to;
          c.target = name("a place name");
        }
        break;
      case 3:  // enter
        c.kind = CommandKind::enter;
        c.place = expect_one({"hall", "room"}) == 0 ? Place::hall : Place::room;
        c.target = name(c.place == Place::hall ? "a hall name" : "a room name");
        break;
      case 4: {  // stop
        expect("at");
        if (accept("the")) {
          c.kind = CommandKind::stop_at_door;
          which_door(c);
          break;
        }
        const std::size_t p =
            expect_one({"door", "corridor", "junction", "corner", "end", "hall", "room"});
        if (p == 0) {
          c.kind = CommandKind::stop_at_door;
          c.target = name("a door name");
          if (const Token* t = peek(); t && t->kind == Tok::open) {
            ++pos_;
            which_door(c);
            const Token* close = peek();
            if (!close || close->kind != Tok::close) fail_here("expected ')'");
            ++pos_;
          }
        } else {
          static const Place places[] = {Place::corridor, Place::junction, Place::corner,
                                         Place::end,      Place::hall,     Place::room};
          c.kind = CommandKind::stop_at_node;
          c.place = places[p - 1];
          c.target = name("a place name");
        }
        break;
      }
    }
    return c;
  }

  void tokenize() {
    const std::string& s = text_;
    // Control characters (NUL, escape, ...) are no part of a command: refused, not read around.
    for (std::size_t k = 0; k < s.size(); ++k) {
      const auto c = static_cast<unsigned char>(s[k]);
      if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7F) {
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02X", c);
        throw CommandParseError(source_, text_, k + 1, hex,
                                std::string("control character ") + hex + " in the text");
      }
    }
    std::size_t i = 0;
    while (i < s.size()) {
      const char ch = s[i];
      const std::size_t col = i + 1;
      if (ch == '\n' || ch == ',' || ch == ';') {
        toks_.push_back({Tok::separator, std::string(1, ch == '\n' ? ' ' : ch), "", col});
        ++i;
      } else if (std::isspace(static_cast<unsigned char>(ch))) {
        ++i;
      } else if (ch == '(' || ch == ')') {
        toks_.push_back({ch == '(' ? Tok::open : Tok::close, std::string(1, ch), "", col});
        ++i;
      } else if (ch == '"') {
        const std::size_t close = s.find('"', i + 1);
        if (close == std::string::npos) {
          throw CommandParseError(source_, text_, col, s.substr(i), "unterminated quoted name");
        }
        const std::string q = s.substr(i + 1, close - i - 1);
        if (q.empty()) throw CommandParseError(source_, text_, col, "\"\"", "empty quoted name");
        if (q.find_first_of("\t\n\r") != std::string::npos)
          throw CommandParseError(source_, text_, col, "\"" + q + "\"",
                                  "a tab or line break inside a quoted name");
        toks_.push_back({Tok::quoted, q, lower(q), col});
        i = close + 1;
      } else {
        std::size_t j = i;
        while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j])) &&
               std::string(",;()\"").find(s[j]) == std::string::npos) {
          ++j;
        }
        std::string w = s.substr(i, j - i);
        // A full stop ends a command: "turn left at the first corner. stop at end E2."
        const bool stop = w.size() > 1 && w.back() == '.';
        if (w == ".") {
          toks_.push_back({Tok::separator, ".", "", col});
        } else {
          if (stop) w.pop_back();
          toks_.push_back({Tok::word, w, lower(w), col});
          if (stop) toks_.push_back({Tok::separator, ".", "", col + w.size()});
        }
        i = j;
      }
    }
  }

  static constexpr const char* kWords[] = {"first", "second",  "third",  "fourth", "fifth",
                                           "sixth", "seventh", "eighth", "ninth",  "tenth"};
  const std::string& text_;
  std::string source_;
  std::vector<Token> toks_;
  std::size_t pos_ = 0;
};

}  // namespace

std::vector<RouteCommand> parse_route_commands(const std::string& text, const std::string& source) {
  return Parser(text, source).parse();
}

void check_commands(const TopologicalMap& map, const std::vector<RouteCommand>& commands,
                    const std::string& source) {
  for (std::size_t i = 0; i < commands.size(); ++i) {
    const RouteCommand& c = commands[i];
    const ErrorContext where{source, "command " + std::to_string(i + 1) + " (" + c.text() + ")",
                             ""};
    if (c.target.empty()) continue;
    if (c.kind == CommandKind::stop_at_door) {
      // A door may be a door node, or a door listed along a corridor.
      if (const Node* n = map.find_node(c.target); n && n->place == Place::door) continue;
      bool listed = false;
      for (const Node& n : map.nodes()) listed = listed || n.find_door(c.target) != nullptr;
      if (!listed) throw InputError(where, "no door named '" + c.target + "' in the map");
      continue;
    }
    const Node* n = map.find_node(c.target);
    if (!n) throw InputError(where, "no place named '" + c.target + "' in the map");
    Place want = n->place;
    switch (c.kind) {
      case CommandKind::follow_corridor:
        want = Place::corridor;
        break;
      case CommandKind::go_through_door:
        want = Place::door;
        break;
      case CommandKind::enter:
      case CommandKind::stop_at_node:
        want = c.place;
        break;
      default:
        break;
    }
    if (n->place != want) {
      throw InputError(
          where, "'" + c.target + "' is a " + to_string(n->place) + ", not a " + to_string(want));
    }
  }
}

}  // namespace lampnav::graph
