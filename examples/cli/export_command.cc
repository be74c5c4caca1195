// placeholder
#include "command.h"

namespace rcm::cli {

extern const Subcommand kExportCommand;
const Subcommand kExportCommand = {"export", "(not yet)", "", {__FILE__},
                                 []() { return kExitFailure; }};

}  // namespace rcm::cli
