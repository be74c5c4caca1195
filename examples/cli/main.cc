// rcm: refractive camera model toolkit. `rcm SUBCOMMAND [flags]`.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <cstring>
#include <iostream>
#include <string>
#include <string_view>

#include "command.h"
#include "rcm/util/heap_padding.h"
#include "rcm/version.h"

namespace rcm::cli {
extern const Subcommand kCalibrateCommand;
extern const Subcommand kCompareCommand;
extern const Subcommand kDemoCommand;
extern const Subcommand kDomeCheckCommand;
extern const Subcommand kEstimateCommand;
extern const Subcommand kExportCommand;
extern const Subcommand kSimulateCommand;
extern const Subcommand kUndistortCommand;
}  // namespace rcm::cli

namespace {

using rcm::cli::Subcommand;

const Subcommand* const kSubcommands[] = {
    &rcm::cli::kCalibrateCommand, &rcm::cli::kCompareCommand,
    &rcm::cli::kDemoCommand,      &rcm::cli::kDomeCheckCommand,
    &rcm::cli::kEstimateCommand,  &rcm::cli::kExportCommand,
    &rcm::cli::kSimulateCommand,  &rcm::cli::kUndistortCommand};

void PrintUsage(std::ostream& out) {
  out << "rcm: the refractive index of the water from a stereo camera "
         "calibrated in air\n\n"
         "usage: rcm SUBCOMMAND [flags]\n\nsubcommands:\n";
  for (const Subcommand* subcommand : kSubcommands) {
    out << "  " << subcommand->name;
    for (size_t i = std::strlen(subcommand->name); i < 12; ++i) out << ' ';
    out << subcommand->summary << "\n";
  }
  out << "\n`rcm SUBCOMMAND --help` lists the flags of a subcommand.\n";
}

}  // namespace

int main(int argc, char** argv) {
  // A pair loop's buffers reuse the heap instead of faulting pages in anew
  // each pair (rcm/util/heap_padding.h).
  rcm::PadHeapGrowth();
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  // A subcommand's errors and warnings are its own one-line messages; the
  // libraries' glog warnings (Ceres on a rank-deficient covariance, which
  // the subcommands report in their own words) stay out of them. CHECK
  // failures (programmer errors) still print.
  FLAGS_minloglevel = google::GLOG_ERROR;
  gflags::SetVersionString(rcm::kVersion);

  if (argc < 2) {
    std::cerr << "rcm: error: no subcommand (try rcm --help)" << std::endl;
    return rcm::cli::kExitUsage;
  }
  const std::string_view name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    PrintUsage(std::cout);
    return rcm::cli::kExitOk;
  }
  if (name == "--version") {
    std::cout << "rcm " << rcm::kVersion << std::endl;
    return rcm::cli::kExitOk;
  }
  for (const Subcommand* subcommand : kSubcommands) {
    if (name != subcommand->name) continue;
    // The subcommand sees "rcm NAME" as its program name.
    std::string program = std::string("rcm ") + subcommand->name;
    argv[1] = program.data();
    int sub_argc = argc - 1;
    char** sub_argv = argv + 1;
    gflags::SetUsageMessage(subcommand->usage);
    const int parsed =
        rcm::cli::ParseSubcommandFlags(*subcommand, &sub_argc, &sub_argv);
    if (parsed >= 0) return parsed;
    return subcommand->run();
  }
  std::cerr << "rcm: error: unknown subcommand '" << name
            << "' (try rcm --help)" << std::endl;
  return rcm::cli::kExitUsage;
}
