#include "rcm/sim/sequence_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "rcm/io/camchain.h"
#include "rcm/io/correspondence_csv.h"
#include "rcm/io/image_file.h"
#include "rcm/sim/reference_rigs.h"
#include "support/temp_file.h"

namespace rcm::sequence_writer_test {
namespace {

namespace fs = std::filesystem;

SequenceOptions MatchesOnly(std::vector<MediaSegment> media,
                            int matches_per_frame) {
  SequenceOptions options;
  options.media = std::move(media);
  options.render_images = false;
  options.matches_per_frame = matches_per_frame;
  return options;
}

TEST(SequenceWriter, WritesTheFolderAndItReadsBack) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  SequenceOptions options;
  options.media = {MediaSegment{1.333, 2}};
  options.render.supersampling = 1;
  options.matches_per_frame = 100;
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig, options).value();
  const std::string folder = test::TempFilePath("sequence");
  fs::remove_all(folder);
  int calls = 0;
  SequenceWriterOptions writer;
  writer.progress = [&](int done, int total) {
    EXPECT_EQ(done, ++calls);
    EXPECT_EQ(total, 2);
  };
  ASSERT_TRUE(WriteSequence(folder, simulator.get(), writer).ok());
  EXPECT_EQ(calls, 2);
  for (const char* name : {"000000.png", "000001.png"}) {
    const cv::Mat left =
        ReadImage(folder + "/left/" + name, /*grayscale=*/true).value();
    EXPECT_EQ(left.size(), cv::Size(720, 540));
    EXPECT_TRUE(fs::exists(folder + "/right/" + name));
  }
  const StereoRig back =
      StereoRigFromCamchain(ReadCamchain(folder + "/camchain.yaml").value(),
                            0, 1)
          .value();
  EXPECT_EQ(back.left(), rig.left());
  const std::vector<StereoCorrespondence> matches =
      ReadCorrespondenceCsv(folder + "/matches.csv").value();
  EXPECT_EQ(matches.size(), 200u);
  std::ifstream truth(folder + "/truth.csv");
  std::string line;
  std::getline(truth, line);
  EXPECT_EQ(line, "frame,t,n,tx,ty,tz,qx,qy,qz,qw");
  std::getline(truth, line);
  EXPECT_EQ(line.rfind("0,0.0,1.333,", 0), 0u) << line;
  std::getline(truth, line);
  EXPECT_EQ(line.rfind("1,0.05,1.333,", 0), 0u) << line;
}

TEST(SequenceWriter, RefusesToOverwriteUnlessAsked) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const std::string folder = test::TempFilePath("sequence");
  fs::remove_all(folder);
  std::unique_ptr<SequenceSimulator> three =
      SequenceSimulator::Create(rig, MatchesOnly({{1.333, 3}}, 20)).value();
  ASSERT_TRUE(WriteSequence(folder, three.get(), {}).ok());
  // Stale frame images of an earlier, longer run.
  fs::create_directories(folder + "/left");
  std::ofstream(folder + "/left/000009.png") << "stale";
  std::ofstream(folder + "/notes.txt") << "mine";

  std::unique_ptr<SequenceSimulator> one =
      SequenceSimulator::Create(rig, MatchesOnly({{1.0, 1}}, 20)).value();
  const Status refused = WriteSequence(folder, one.get(), {});
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("--overwrite"), std::string::npos);
  EXPECT_EQ(ReadCorrespondenceCsv(folder + "/matches.csv").value().size(),
            60u);  // untouched

  SequenceWriterOptions overwrite;
  overwrite.overwrite = true;
  ASSERT_TRUE(WriteSequence(folder, one.get(), overwrite).ok());
  EXPECT_EQ(ReadCorrespondenceCsv(folder + "/matches.csv").value().size(),
            20u);
  EXPECT_FALSE(fs::exists(folder + "/left/000009.png"));
  EXPECT_TRUE(fs::exists(folder + "/notes.txt"));
}

TEST(SequenceWriter, UnwritableFolderIsOneLineError) {
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(AlphasenseFrontRectifiedRig(),
                                MatchesOnly({{1.333, 1}}, 10))
          .value();
  const std::string file = test::WriteTempFile("a_file", "x");
  const Status status = WriteSequence(file + "/sub", simulator.get(), {});
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message().find('\n'), std::string::npos);
  const Status not_folder = WriteSequence(file, simulator.get(), {});
  ASSERT_FALSE(not_folder.ok());
  EXPECT_NE(not_folder.message().find("not a folder"), std::string::npos);
}

TEST(SequenceWriter, WritesTheBoardAndTheCalibrationNotTheDrift) {
  // board.csv has one row per frame, cam0_from_target and the two flags;
  // camchain.yaml is the nominal rig, whatever the drift.
  const StereoRig rig = NarrowFieldRig();
  SequenceOptions options = MatchesOnly({MediaSegment{1.34, 3}}, 20);
  options.board = SceneBoard();
  options.cam1_drift.rotation = Eigen::Vector3d(0.0, 0.5, 0.0) * M_PI / 180.0;
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig, options).value();
  const std::string folder = test::TempFilePath("board_sequence");
  fs::remove_all(folder);
  ASSERT_TRUE(WriteSequence(folder, simulator.get(), {}).ok());
  std::ifstream board(folder + "/board.csv");
  std::string line;
  std::getline(board, line);
  EXPECT_EQ(line, "frame,t,tx,ty,tz,qx,qy,qz,qw,visible_left,visible_right");
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(std::getline(board, line));
    EXPECT_EQ(line.rfind(std::to_string(i) + ",", 0), 0u) << line;
    EXPECT_EQ(line.substr(line.size() - 4), ",1,1") << line;
  }
  EXPECT_FALSE(std::getline(board, line));
  std::ifstream whole(folder + "/board.csv");
  std::stringstream text;
  text << whole.rdbuf();
  EXPECT_EQ(FormatBoardCsv(*simulator), text.str());
  const StereoRig written =
      StereoRigFromCamchain(ReadCamchain(folder + "/camchain.yaml").value(), 0,
                            1)
          .value();
  EXPECT_TRUE(written.right_from_left().rotation.isApprox(
      rig.right_from_left().rotation, 1e-15));
  // A sequence without a board replaces the old board.csv (overwrite).
  std::unique_ptr<SequenceSimulator> plain =
      SequenceSimulator::Create(rig, MatchesOnly({MediaSegment{1.34, 1}}, 5))
          .value();
  SequenceWriterOptions overwrite;
  overwrite.overwrite = true;
  ASSERT_TRUE(WriteSequence(folder, plain.get(), overwrite).ok());
  EXPECT_FALSE(fs::exists(folder + "/board.csv"));
}

}  // namespace
}  // namespace rcm::sequence_writer_test
