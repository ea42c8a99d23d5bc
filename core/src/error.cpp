#include "lampnav/core/error.hpp"

namespace lampnav {

std::string format_problem(const ErrorContext& where, const std::string& message) {
  std::string out;
  for (const std::string* part : {&where.file, &where.place, &where.field}) {
    if (part->empty()) continue;
    out += *part;
    out += ": ";
  }
  return out + message;
}

InputError::InputError(ErrorContext where, std::string message)
    : Error(format_problem(where, message)),
      where_(std::move(where)),
      message_(std::move(message)) {}

namespace {
std::string summarize(const std::vector<InputError>& problems) {
  if (problems.empty()) return "no problems";
  std::string s = problems.front().what();
  if (problems.size() > 1) {
    s += " (and " + std::to_string(problems.size() - 1) + " more problem" +
         (problems.size() > 2 ? "s" : "") + ")";
  }
  return s;
}
}  // namespace

InputErrors::InputErrors(std::vector<InputError> problems)
    : Error(summarize(problems)), problems_(std::move(problems)) {}

}  // namespace lampnav
