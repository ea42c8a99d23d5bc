#pragma once
// Strict reading of lampnav's JSON formats: every access names the file, the place and the field
// path it was made at, so any refusal reads "maps/x.geojson: feature 3 (id 12):
// properties.metadata.lamps[1].xyz: ..." Internal to the library (nlohmann stays out of the
// public headers).

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "lampnav/core/error.hpp"

namespace lampnav::json {

using Json = nlohmann::json;

// Reads a whole file; a missing or unreadable file is an InputError naming it.
std::string read_file(const std::string& path);
// Writes a whole file; one that cannot be written is an InputError naming it.
void write_file(const std::string& path, const std::string& text);

// Parses JSON text; a syntax error is an InputError giving line and column.
Json parse(const std::string& text, const std::string& file);

// 1-based line and column of a byte offset in text.
std::pair<std::size_t, std::size_t> line_column(const std::string& text, std::size_t offset);

// A position in a JSON document: the value, and where it is (file, place, field path).
class Cursor {
 public:
  Cursor(const Json& value, ErrorContext where) : value_(&value), where_(std::move(where)) {}

  const Json& value() const { return *value_; }
  const ErrorContext& where() const { return where_; }

  // The member `key` of this object: an error if this is not an object or the key is missing.
  Cursor at(const char* key) const;
  // The member `key` if present (and not null is NOT implied: null is returned as present).
  std::optional<Cursor> find(const char* key) const;
  // Element i of this array.
  Cursor operator[](std::size_t i) const;

  void expect_object() const;
  // Refuses any member not in `allowed`: a misspelt key must not silently vanish.
  void only_keys(std::initializer_list<const char*> allowed) const;
  // Checks that this is an array, optionally of an exact size or a size range.
  std::size_t array_size(std::size_t min = 0, std::size_t max = SIZE_MAX) const;

  double number() const;         // finite number
  double positive() const;       // finite and > 0
  std::int64_t integer() const;  // integral number
  std::string string() const;    // non-empty string
  bool boolean() const;

  [[noreturn]] void fail(const std::string& message) const;

 private:
  Cursor child(const std::string& field_suffix, const Json& v) const;

  const Json* value_;
  ErrorContext where_;
};

}  // namespace lampnav::json
