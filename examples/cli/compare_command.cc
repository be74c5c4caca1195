// placeholder
#include "command.h"

namespace rcm::cli {

extern const Subcommand kCompareCommand;
const Subcommand kCompareCommand = {"compare", "(not yet)", "", {__FILE__},
                                 []() { return kExitFailure; }};

}  // namespace rcm::cli
