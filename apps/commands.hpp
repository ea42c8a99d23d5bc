#pragma once
// Subcommands of the `lampnav` program. Each registers itself on the app and sets `run` to the
// job to do once the command line is parsed; the job returns the exit status (cli.md) and
// throws lampnav errors, which main() turns into messages.

#include <functional>
#include <iosfwd>
#include <string>

namespace CLI {
class App;
}

namespace lampnav::apps {

using Job = std::function<int()>;

void add_map_commands(CLI::App& app, Job& run);
void add_route_command(CLI::App& app, Job& run);
void add_sim_command(CLI::App& app, Job& run);
void add_locate_command(CLI::App& app, Job& run);

// Prints a diagnostic line to stderr: "lampnav: <kind>: <text>".
void diagnostic(const std::string& kind, const std::string& text);

}  // namespace lampnav::apps
