#pragma once
// The errors the library throws. Library code never prints and never exits: it throws one of
// these, carrying the file, the place in it and the field it is about, and the program turns it
// into a message and an exit status.

#include <stdexcept>
#include <string>
#include <vector>

namespace lampnav {

// Where a problem is: the file, the place in it ("line 3, column 7", "feature 4 (id 12)",
// "camera 1 (omni_camera)") and the field ("properties.metadata.region"). Any may be empty.
struct ErrorContext {
  std::string file;
  std::string place;
  std::string field;
};

// "file: place: field: message", leaving out the parts that are empty.
std::string format_problem(const ErrorContext& where, const std::string& message);

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// Bad input from outside (a map, robot.json, a log, an image, command text, a flag): exit status 2.
class InputError : public Error {
 public:
  InputError(ErrorContext where, std::string message);
  const ErrorContext& where() const { return where_; }
  const std::string& message() const { return message_; }

 private:
  ErrorContext where_;
  std::string message_;
};

// Several input problems found in one pass (a map reader reports them all, not just the first).
// what() is the first problem followed by a count of the rest.
class InputErrors : public Error {
 public:
  explicit InputErrors(std::vector<InputError> problems);
  const std::vector<InputError>& problems() const { return problems_; }

 private:
  std::vector<InputError> problems_;
};

// The job ran and could not succeed (no route between two places, robot lost): exit status 1.
class JobFailed : public Error {
 public:
  explicit JobFailed(const std::string& message) : Error(message) {}
};

}  // namespace lampnav
