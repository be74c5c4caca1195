#include "glass_index_flag.h"

DEFINE_double(glass_index, 1.49,
              "port: refractive index of the glass, of a flat port or a "
              "dome (acrylic 1.49, borosilicate 1.47, BK7 1.517)");

namespace rcm::cli {

extern const char kGlassIndexFlagSource[] = __FILE__;

}  // namespace rcm::cli
