#include "command.h"

#include <gflags/gflags.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

// Flags every subcommand shares.
DEFINE_bool(json, false, "print one JSON object on stdout instead of text");
DEFINE_string(out, "",
              "output folder (rcm simulate: required; rcm demo: default "
              "./rcm_demo; rcm estimate: optional, for the pictures and "
              "files of the run; rcm calibrate: the camchain file to write, "
              "or a folder)");

namespace rcm::cli {
namespace {

bool IsHelpFlag(std::string_view arg) {
  return arg == "-h" || arg == "--help" || arg == "-help" ||
         arg == "--helpfull";
}

// Flags are defined with underscores (gflags' convention) and shown with
// dashes; gflags accepts both spellings on the command line.
std::string DashedName(std::string name) {
  std::replace(name.begin(), name.end(), '_', '-');
  return name;
}

// Flags of this file and of the subcommand's flag files.
bool OwnsFlag(const Subcommand& subcommand,
              const gflags::CommandLineFlagInfo& flag) {
  if (flag.filename == __FILE__) return true;
  for (const char* source : subcommand.flag_sources) {
    if (flag.filename == source) return true;
  }
  return false;
}

void PrintHelp(const Subcommand& subcommand) {
  std::cout << subcommand.usage << "\n\nFlags:\n";
  std::vector<gflags::CommandLineFlagInfo> flags;
  gflags::GetAllFlags(&flags);
  std::sort(flags.begin(), flags.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  for (const gflags::CommandLineFlagInfo& flag : flags) {
    if (!OwnsFlag(subcommand, flag)) continue;
    std::cout << "  --" << DashedName(flag.name);
    if (flag.type != "bool") std::cout << "=" << flag.type;
    std::cout << "\n      " << flag.description;
    if (!flag.default_value.empty() && flag.default_value != "false") {
      std::cout << " (default: " << flag.default_value << ")";
    }
    std::cout << "\n";
  }
  std::cout << "  --help\n      show this help\n";
}

}  // namespace

int ParseSubcommandFlags(const Subcommand& subcommand, int* argc,
                         char*** argv) {
  for (int i = 1; i < *argc; ++i) {
    if (std::strcmp((*argv)[i], "--") == 0) break;
    if (IsHelpFlag((*argv)[i])) {
      PrintHelp(subcommand);
      return kExitOk;
    }
  }
  // Flags of other subcommands, and those of libraries (glog), are not part
  // of this subcommand's interface: reject them by the names typed.
  for (int i = 1; i < *argc; ++i) {
    std::string_view arg = (*argv)[i];
    if (arg == "--") break;
    if (arg.size() < 2 || arg[0] != '-') continue;
    arg.remove_prefix(arg[1] == '-' ? 2 : 1);
    std::string name(arg.substr(0, arg.find('=')));
    std::replace(name.begin(), name.end(), '-', '_');
    gflags::CommandLineFlagInfo flag;
    bool found = gflags::GetCommandLineFlagInfo(name.c_str(), &flag);
    if (!found && name.rfind("no", 0) == 0) {
      name = name.substr(2);  // --noflag sets a bool flag to false
      found = gflags::GetCommandLineFlagInfo(name.c_str(), &flag);
    }
    if (!found) continue;  // unknown: gflags reports it below
    if (!OwnsFlag(subcommand, flag)) {
      PrintError(subcommand, "--" + DashedName(name) +
                                 " is not a flag of rcm " + subcommand.name +
                                 " (see rcm " + subcommand.name + " --help)");
      return kExitUsage;
    }
  }
  // gflags prints "ERROR: unknown command line flag 'x'" and exits 1 on an
  // unknown flag.
  gflags::ParseCommandLineFlags(argc, argv, /*remove_flags=*/true);
  if (*argc > 1) {
    PrintError(subcommand, std::string("unexpected argument '") + (*argv)[1] +
                               "' (see rcm " + subcommand.name + " --help)");
    return kExitUsage;
  }
  return -1;
}

void PrintError(const Subcommand& subcommand, const std::string& message) {
  std::cerr << "rcm " << subcommand.name << ": error: " << message << std::endl;
}

void PrintWarning(const Subcommand& subcommand, const std::string& message) {
  std::cerr << "rcm " << subcommand.name << ": warning: " << message
            << std::endl;
}

nlohmann::json JsonNumber(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json();
}

nlohmann::json JsonNumber(const std::optional<double>& value) {
  return value ? JsonNumber(*value) : nlohmann::json();
}

}  // namespace rcm::cli
