#include "rcm/sim/thin_port_bias.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "rcm/sim/reference_rigs.h"

namespace rcm::thin_port_bias_test {
namespace {

FlatPort Port(double air_gap_mm, double glass_mm) {
  FlatPort port;
  port.air_gap = air_gap_mm * 1e-3;
  port.glass_thickness = glass_mm * 1e-3;
  return port;
}

TEST(ThinPortBias, ThinPortIsUnbiased) {
  const ThinPortBias bias =
      MeasureThinPortBias(AlphasenseFrontRectifiedRig(), FlatPort(),
                          ThinPortBiasOptions())
          .value();
  EXPECT_LT(std::abs(bias.bias), 1e-9);
  EXPECT_LT(bias.rms_residual, 1e-6);
  EXPECT_EQ(bias.inliers, 2000);
  EXPECT_EQ(bias.n_thick, bias.n_thin);  // a thin port: the same model
}

TEST(ThinPortBias, AirGapBiasesTheEstimateDown) {
  // The thin model explains the gap's extra lateral offset with a smaller
  // bending: the bias is negative and grows with the gap, and the thin
  // model visibly misfits (nonzero residuals on exact data).
  double previous = 0.0;
  for (const double gap_mm : {2.0, 5.0, 10.0, 20.0}) {
    const ThinPortBias bias =
        MeasureThinPortBias(AlphasenseFrontRectifiedRig(), Port(gap_mm, 0.0),
                            ThinPortBiasOptions())
            .value();
    EXPECT_LT(bias.bias, previous) << gap_mm << " mm";
    EXPECT_GT(bias.rms_residual, 0.0);
    // Told about the port, the estimate is exact.
    EXPECT_LT(std::abs(bias.thick_bias), 1e-9) << gap_mm << " mm";
    previous = bias.bias;
  }
}

TEST(ThinPortBias, RejectsInvalidInput) {
  ThinPortBiasOptions options;
  options.num_matches = 5;
  EXPECT_FALSE(MeasureThinPortBias(AlphasenseFrontRectifiedRig(), FlatPort(),
                                   options)
                   .ok());
  options = ThinPortBiasOptions();
  options.n = 2.5;
  EXPECT_FALSE(MeasureThinPortBias(AlphasenseFrontRectifiedRig(), FlatPort(),
                                   options)
                   .ok());
  EXPECT_FALSE(MeasureThinPortBias(AlphasenseFrontRectifiedRig(),
                                   Port(-1.0, 0.0), ThinPortBiasOptions())
                   .ok());
}

// Cells "+0.0123" of a Markdown table row "| 5 mm | +0.0123 | ... |".
std::vector<std::string> Cells(const std::string& row) {
  std::vector<std::string> cells;
  std::stringstream stream(row);
  std::string cell;
  while (std::getline(stream, cell, '|')) {
    const size_t begin = cell.find_first_not_of(' ');
    if (begin == std::string::npos) continue;
    cells.push_back(cell.substr(begin, cell.find_last_not_of(' ') - begin + 1));
  }
  return cells;
}

TEST(ThinPortBias, DocsTableIsCurrent) {
  // The table of docs/thin_port_bias.md is examples/api/thin_port_bias_table
  // run with its defaults (the defaults of ThinPortBiasOptions). Every cell
  // is recomputed: the thin-port biases are printed with 4 decimals, so
  // they agree to 5e-5; the last column, the thick-port model's largest
  // |bias| over the row, is printed as "1e-12" and must stay below the
  // 1e-9 of the exact tests, as must its recomputation.
  constexpr double kPrintedPrecision = 5e-5 + 1e-9;
  constexpr double kThickTolerance = 1e-9;
  const std::string path =
      std::string(RCM_SOURCE_DIR) + "/docs/thin_port_bias.md";
  std::ifstream page(path);
  ASSERT_TRUE(page.good()) << "cannot read " << path;
  std::string line;
  while (std::getline(page, line) &&
         line.find("<!-- thin-port-bias-table -->") == std::string::npos) {
  }
  ASSERT_TRUE(page.good()) << path << " has no thin-port-bias-table marker";
  std::getline(page, line);  // | air gap \ glass | 0 mm | ... | thick |
  const std::vector<std::string> header = Cells(line);
  ASSERT_GE(header.size(), 4u);
  EXPECT_EQ(header.back(), "thick-port model, any glass");
  std::vector<double> glass_mm;
  for (size_t i = 1; i + 1 < header.size(); ++i) {
    glass_mm.push_back(std::stod(header[i]));
  }
  std::getline(page, line);  // |---|---|
  int rows = 0;
  while (std::getline(page, line) && line.rfind("|", 0) == 0) {
    const std::vector<std::string> cells = Cells(line);
    ASSERT_EQ(cells.size(), glass_mm.size() + 2) << line;
    const double gap_mm = std::stod(cells[0]);
    double thick_bias = 0.0;
    for (size_t j = 0; j < glass_mm.size(); ++j) {
      const ThinPortBias bias =
          MeasureThinPortBias(AlphasenseFrontRectifiedRig(),
                              Port(gap_mm, glass_mm[j]), ThinPortBiasOptions())
              .value();
      EXPECT_NEAR(std::stod(cells[j + 1]), bias.bias, kPrintedPrecision)
          << "gap " << gap_mm << " mm, glass " << glass_mm[j] << " mm";
      thick_bias = std::max(thick_bias, std::abs(bias.thick_bias));
    }
    EXPECT_LT(std::stod(cells.back()), kThickTolerance) << line;
    EXPECT_LT(thick_bias, kThickTolerance) << "gap " << gap_mm << " mm";
    ++rows;
  }
  EXPECT_GE(rows, 5);
}

}  // namespace
}  // namespace rcm::thin_port_bias_test
