#include "lampnav/internal/json_util.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace lampnav::json {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, "", ""}, "cannot open the file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError({path, "", ""}, "read error");
  return ss.str();
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError({path, "", ""}, "cannot write the file");
  out << text;
  if (!out.flush()) throw InputError({path, "", ""}, "write failed");
}

std::pair<std::size_t, std::size_t> line_column(const std::string& text, std::size_t offset) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

Json parse(const std::string& text, const std::string& file) {
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    // nlohmann reports the byte just past the offending token (1-based); point at that byte.
    const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
    const auto [line, column] = line_column(text, offset);
    std::string why = e.what();
    // Keep nlohmann's explanation, drop its "[json.exception.parse_error.101] parse error at..."
    // prefix, which repeats the position we already give.
    const auto colon = why.find(": syntax error");
    if (colon != std::string::npos) why = why.substr(colon + 2);
    throw InputError(
        {file, "line " + std::to_string(line) + ", column " + std::to_string(column), ""},
        "not valid JSON: " + why);
  } catch (const Json::out_of_range& e) {
    // A number too large for a double ("1e999"): nlohmann names the token but not its place.
    const std::string what = e.what();
    const auto q1 = what.find('\'');
    const auto q2 = q1 == std::string::npos ? q1 : what.find('\'', q1 + 1);
    std::string place;
    std::string token;
    if (q2 != std::string::npos) {
      token = what.substr(q1 + 1, q2 - q1 - 1);
      const auto at = text.find(token);
      if (at != std::string::npos) {
        const auto [line, column] = line_column(text, at);
        place = "line " + std::to_string(line) + ", column " + std::to_string(column);
      }
    }
    throw InputError({file, place, ""},
                     "not a finite number" + (token.empty() ? std::string() : ": " + token));
  }
}

Cursor Cursor::child(const std::string& field_suffix, const Json& v) const {
  ErrorContext w = where_;
  if (field_suffix.front() == '[' || w.field.empty()) {
    w.field += field_suffix;
  } else {
    w.field += "." + field_suffix;
  }
  return Cursor(v, std::move(w));
}

void Cursor::fail(const std::string& message) const { throw InputError(where_, message); }

void Cursor::expect_object() const {
  if (!value_->is_object()) fail(std::string("expected an object, found ") + value_->type_name());
}

Cursor Cursor::at(const char* key) const {
  expect_object();
  auto it = value_->find(key);
  if (it == value_->end()) child(key, *value_).fail("missing");
  return child(key, *it);
}

std::optional<Cursor> Cursor::find(const char* key) const {
  expect_object();
  auto it = value_->find(key);
  if (it == value_->end()) return std::nullopt;
  return child(key, *it);
}

Cursor Cursor::operator[](std::size_t i) const {
  return child("[" + std::to_string(i) + "]", value_->at(i));
}

void Cursor::only_keys(std::initializer_list<const char*> allowed) const {
  expect_object();
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    bool known = false;
    for (const char* a : allowed) known = known || it.key() == a;
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      child(it.key(), it.value())
          .fail(list.empty() ? "unknown key (this object takes no keys)"
                             : "unknown key (expected one of: " + list + ")");
    }
  }
}

std::size_t Cursor::array_size(std::size_t min, std::size_t max) const {
  if (!value_->is_array()) fail(std::string("expected an array, found ") + value_->type_name());
  const std::size_t n = value_->size();
  if (n < min || n > max) {
    if (min == max)
      fail("expected " + std::to_string(min) + " elements, found " + std::to_string(n));
    if (max == SIZE_MAX) {
      fail("expected at least " + std::to_string(min) + " elements, found " + std::to_string(n));
    }
    fail("expected " + std::to_string(min) + " to " + std::to_string(max) + " elements, found " +
         std::to_string(n));
  }
  return n;
}

double Cursor::number() const {
  if (!value_->is_number()) fail(std::string("expected a number, found ") + value_->type_name());
  const double v = value_->get<double>();
  if (!std::isfinite(v)) fail("not a finite number");
  return v;
}

double Cursor::positive() const {
  const double v = number();
  if (!(v > 0.0)) fail("must be greater than zero, found " + value_->dump());
  return v;
}

std::int64_t Cursor::integer() const {
  if (value_->is_number_integer()) return value_->get<std::int64_t>();
  if (value_->is_number_float()) {
    const double v = value_->get<double>();
    if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 9.0e15) {
      return static_cast<std::int64_t>(v);
    }
  }
  fail("expected an integer, found " + value_->dump());
}

std::string Cursor::string() const {
  if (!value_->is_string()) fail(std::string("expected a string, found ") + value_->type_name());
  std::string s = value_->get<std::string>();
  if (s.empty()) fail("must not be empty");
  return s;
}

bool Cursor::boolean() const {
  if (!value_->is_boolean())
    fail(std::string("expected true or false, found ") + value_->type_name());
  return value_->get<bool>();
}

}  // namespace lampnav::json
