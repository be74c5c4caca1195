// API example: when does the paper's thin-port model hold? Prints, as a
// Markdown table, the bias of the thin-port estimate of n for housings with
// an air gap between lens and glass and a glass plate of some thickness,
// from exact noise-free correspondences (rcm/sim/thin_port_bias.h), and in
// the last column the largest |bias| over the glass thicknesses of the
// estimate that is given the port (the thick-port model).
//
// The approximation table of docs/thin_port_bias.md is its output with the
// defaults; a test recomputes every cell of that table.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "rcm/io/stereo_rig_file.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/thin_port_bias.h"

DEFINE_string(calib, "",
              "Kalibr camchain YAML of the rig (default: the dataset rig of "
              "docs/design.md Sec. 6 on rectified extrinsics)");
DEFINE_double(n, 1.333, "true refractive index of the water");
DEFINE_double(glass_index, 1.49, "refractive index of the port glass");
DEFINE_double(min_depth, 0.6, "nearest scene depth (m)");
DEFINE_double(max_depth, 6.0, "farthest scene depth (m)");
DEFINE_string(gaps_mm, "0,1,2,5,10,20,30", "air gaps (mm), comma-separated");
DEFINE_string(glass_mm, "0,5,10", "glass thicknesses (mm), comma-separated");

namespace {

std::vector<double> ParseList(const std::string& text) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) values.push_back(std::stod(item));
  return values;
}

}  // namespace

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  gflags::SetUsageMessage(
      "thin_port_bias_table [--calib RIG.yaml] [--n 1.333] "
      "[--gaps-mm 0,5,10] [--glass-mm 0,5]");
  gflags::ParseCommandLineFlags(&argc, &argv, true);

  rcm::StatusOr<rcm::StereoRig> rig = rcm::AlphasenseFrontRectifiedRig();
  if (!FLAGS_calib.empty()) rig = rcm::ReadStereoRig(FLAGS_calib);
  if (!rig.ok()) {
    std::cerr << "thin_port_bias_table: error: " << rig.status().message()
              << std::endl;
    return 1;
  }
  std::vector<double> gaps;
  std::vector<double> glass;
  try {
    gaps = ParseList(FLAGS_gaps_mm);
    glass = ParseList(FLAGS_glass_mm);
  } catch (const std::exception&) {
    std::cerr << "thin_port_bias_table: error: --gaps-mm and --glass-mm are "
                 "comma-separated numbers"
              << std::endl;
    return 2;
  }

  rcm::ThinPortBiasOptions options;
  options.n = FLAGS_n;
  options.min_depth = FLAGS_min_depth;
  options.max_depth = FLAGS_max_depth;
  std::printf("| air gap \\ glass |");
  for (const double g : glass) std::printf(" %g mm |", g);
  std::printf(" thick-port model, any glass |\n|---|");
  for (size_t i = 0; i <= glass.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const double gap : gaps) {
    std::printf("| %g mm |", gap);
    double thick_bias = 0.0;  // the largest |bias| of the thick-port model
    for (const double g : glass) {
      rcm::FlatPort port;
      port.air_gap = gap * 1e-3;
      port.glass_thickness = g * 1e-3;
      port.glass_index = FLAGS_glass_index;
      const rcm::StatusOr<rcm::ThinPortBias> bias =
          rcm::MeasureThinPortBias(rig.value(), port, options);
      if (!bias.ok()) {
        std::cerr << "thin_port_bias_table: error: " << bias.status().message()
                  << std::endl;
        return 1;
      }
      std::printf(" %+.4f |", bias.value().bias);
      thick_bias = std::max(thick_bias, std::abs(bias.value().thick_bias));
    }
    std::printf(" %.0e |\n", thick_bias);
  }
  return 0;
}
