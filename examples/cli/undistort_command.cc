// placeholder
#include "command.h"

namespace rcm::cli {

extern const Subcommand kUndistortCommand;
const Subcommand kUndistortCommand = {"undistort", "(not yet)", "", {__FILE__},
                                 []() { return kExitFailure; }};

}  // namespace rcm::cli
