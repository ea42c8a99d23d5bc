#include "nav2_rules.hpp"

#include <string>

namespace lampnav::graph::nav2 {

using json::Cursor;
using json::Json;

namespace {

bool scalar(const Json& v) { return v.is_number() || v.is_boolean() || v.is_string(); }

}  // namespace

void check_metadata(const Cursor& metadata) {
  metadata.expect_object();
  for (auto it = metadata.value().begin(); it != metadata.value().end(); ++it) {
    const Cursor member = metadata.at(it.key().c_str());
    const Json& v = member.value();
    if (v.is_object()) {
      check_metadata(member);
    } else if (v.is_array()) {
      for (std::size_t i = 0; i < v.size(); ++i) {
        if (!scalar(v[i])) {
          member[i].fail(std::string("Nav2's route graph loader cannot convert an array of ") +
                         v[i].type_name() +
                         "s (only numbers, booleans or strings); lampnav's own data goes under "
                         "properties.lampnav (map-format.md)");
        }
      }
    } else if (!scalar(v)) {
      member.fail(std::string("Nav2's route graph loader cannot convert a ") + v.type_name() +
                  " (only numbers, booleans, strings, objects and arrays of scalars)");
    }
  }
}

void check_operations(const Cursor& operations) {
  const Json& ops = operations.value();
  if (!ops.is_object() && !ops.is_array())
    operations.fail(std::string("expected an object or an array of operations, found ") +
                    ops.type_name());
  auto check_one = [](const Cursor& op) {
    op.only_keys({"type", "trigger", "metadata"});
    op.at("type").string();
    const std::string trigger = op.at("trigger").string();
    if (trigger != "NODE" && trigger != "ON_ENTER" && trigger != "ON_EXIT") {
      op.at("trigger").fail("unknown trigger \"" + trigger +
                            "\" (expected NODE, ON_ENTER or ON_EXIT; Nav2 would read it as NODE)");
    }
    if (auto md = op.find("metadata")) check_metadata(*md);
  };
  if (ops.is_array()) {
    for (std::size_t i = 0; i < ops.size(); ++i) check_one(operations[i]);
  } else {
    for (auto it = ops.begin(); it != ops.end(); ++it) check_one(operations.at(it.key().c_str()));
  }
}

std::int64_t id(const Cursor& c) {
  const std::int64_t v = c.integer();
  if (v < 0 || v > 0xffffffffLL)
    c.fail("must be an integer from 0 to 4294967295 (Nav2 reads ids as unsigned 32-bit), found " +
           std::to_string(v));
  return v;
}

}  // namespace lampnav::graph::nav2
