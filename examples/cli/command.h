// The subcommand machinery of the `rcm` executable: each subcommand lives
// in its own file, defines its gflags there, and is listed in main.cc.
#ifndef RCM_EXAMPLES_CLI_COMMAND_H_
#define RCM_EXAMPLES_CLI_COMMAND_H_

#include <gflags/gflags.h>

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

// Flags every subcommand has (defined in command.cc).
DECLARE_bool(json);
DECLARE_string(out);

namespace rcm::cli {

// Exit codes of every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;  // bad input, nothing to estimate
inline constexpr int kExitUsage = 2;    // wrong flags

struct Subcommand {
  const char* name;     // e.g. "estimate"
  const char* summary;  // one line for `rcm --help`
  const char* usage;    // the text of `rcm NAME --help` above the flags
  // __FILE__ of each file whose flags it takes: its own file, then shared
  // flag files (rig_flags.cc, simulation_flags.cc). The flags of
  // command.cc (--json) belong to every subcommand.
  std::vector<const char*> flag_sources;
  int (*run)();  // runs after the flags are parsed
};

// Parses the flags of `subcommand` from argv (argv[0] = "rcm NAME"),
// handles --help, and rejects flags that belong to other subcommands.
// Returns the exit code to stop with, or -1 to go on and run it.
int ParseSubcommandFlags(const Subcommand& subcommand, int* argc, char*** argv);

// A JSON number, or null when `value` is not finite (or absent): JSON has
// no NaN or infinity.
nlohmann::json JsonNumber(double value);
nlohmann::json JsonNumber(const std::optional<double>& value);

// Writes "rcm NAME: error: MESSAGE" as one line on stderr.
void PrintError(const Subcommand& subcommand, const std::string& message);
// Writes "rcm NAME: warning: MESSAGE" as one line on stderr.
void PrintWarning(const Subcommand& subcommand, const std::string& message);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_COMMAND_H_
