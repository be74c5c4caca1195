#include "rcm/sim/sequence_writer.h"

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <utility>
#include <vector>

#include "rcm/io/atomic_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/correspondence_csv.h"
#include "rcm/io/image_file.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSequenceFiles[] = {"matches.csv", "camchain.yaml",
                                          "board.csv", "truth.csv"};
constexpr const char* kImageFolders[] = {"left", "right"};

// True when `folder` holds a file or image folder of a sequence.
bool HoldsSequence(const fs::path& folder) {
  std::error_code error;
  for (const char* name : kSequenceFiles) {
    if (fs::exists(folder / name, error)) return true;
  }
  for (const char* name : kImageFolders) {
    if (fs::exists(folder / name, error)) return true;
  }
  return false;
}

// Removes the files an earlier sequence left: the four files and the
// frame images (six digits + .png) in left/ and right/. Other files stay.
Status RemoveSequence(const fs::path& folder) {
  std::error_code error;
  for (const char* name : kSequenceFiles) fs::remove(folder / name, error);
  for (const char* name : kImageFolders) {
    const fs::path images = folder / name;
    if (!fs::is_directory(images, error)) continue;
    std::vector<fs::path> frames;
    for (const fs::directory_entry& entry :
         fs::directory_iterator(images, error)) {
      const std::string file = entry.path().filename().string();
      if (file.size() == 10 && file.substr(6) == ".png") {
        frames.push_back(entry.path());
      }
    }
    for (const fs::path& frame : frames) {
      if (!fs::remove(frame, error) && error) {
        return Status::Error("cannot remove " + frame.string() + ": " +
                             error.message());
      }
    }
  }
  return Status::Ok();
}

Status MakeFolder(const fs::path& folder) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) {
    return Status::Error("cannot create folder " + folder.string() + ": " +
                         error.message());
  }
  return Status::Ok();
}

}  // namespace

std::string SequenceImageName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return name;
}

namespace {

// ",tx,ty,tz,qx,qy,qz,qw" of a pose (Hamilton quaternion).
void AppendPose(const Rigid3d& pose, std::string* text) {
  const Eigen::Quaterniond q(pose.rotation);
  const Eigen::Vector3d& p = pose.translation;
  for (const double value : {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()}) {
    *text += ',';
    *text += FormatDouble(value);
  }
}

}  // namespace

std::string FormatTruthCsv(const SequenceSimulator& simulator) {
  std::string text = "frame,t,n,tx,ty,tz,qx,qy,qz,qw\n";
  for (int i = 0; i < simulator.num_frames(); ++i) {
    const TimedPose& pose = simulator.poses()[i];
    text += std::to_string(i);
    for (const double value : {pose.t, simulator.n_of_frame()[i]}) {
      text += ',';
      text += FormatDouble(value);
    }
    AppendPose(pose.world_from_cam0, &text);
    text += '\n';
  }
  return text;
}

std::string FormatBoardCsv(const SequenceSimulator& simulator) {
  std::string text =
      "frame,t,tx,ty,tz,qx,qy,qz,qw,visible_left,visible_right\n";
  const std::vector<BoardFrame>& frames = simulator.board_frames();
  for (size_t i = 0; i < frames.size(); ++i) {
    text += std::to_string(i) + ',' + FormatDouble(simulator.poses()[i].t);
    AppendPose(frames[i].cam0_from_target, &text);
    for (const bool visible : frames[i].fully_visible) {
      text += visible ? ",1" : ",0";
    }
    text += '\n';
  }
  return text;
}

Status WriteSequence(const std::string& folder, SequenceSimulator* simulator,
                     const SequenceWriterOptions& options) {
  CHECK(simulator != nullptr);
  const fs::path root(folder);
  std::error_code error;
  if (fs::exists(root, error) && !fs::is_directory(root, error)) {
    return Status::Error(folder + " exists and is not a folder");
  }
  if (HoldsSequence(root)) {
    if (!options.overwrite) {
      return Status::Error(folder +
                           " already holds a sequence (pass --overwrite to "
                           "replace it)");
    }
    RCM_RETURN_IF_ERROR(RemoveSequence(root));
  }
  RCM_RETURN_IF_ERROR(MakeFolder(root));
  const bool images = simulator->options().render_images;
  if (images) {
    RCM_RETURN_IF_ERROR(MakeFolder(root / "left"));
    RCM_RETURN_IF_ERROR(MakeFolder(root / "right"));
  }

  std::vector<StereoCorrespondence> matches;
  for (int i = 0; i < simulator->num_frames(); ++i) {
    StatusOr<SequenceFrame> frame = simulator->Frame(i);
    if (!frame.ok()) {
      return frame.status().WithContext("frame " + std::to_string(i));
    }
    if (images) {
      const std::string name = SequenceImageName(i);
      RCM_RETURN_IF_ERROR(
          WritePng(frame.value().left, (root / "left" / name).string()));
      RCM_RETURN_IF_ERROR(
          WritePng(frame.value().right, (root / "right" / name).string()));
    }
    matches.insert(matches.end(), frame.value().matches.begin(),
                   frame.value().matches.end());
    if (options.progress) options.progress(i + 1, simulator->num_frames());
  }
  if (simulator->options().matches_per_frame > 0) {
    if (matches.empty()) {
      return Status::Error(
          "no point of the tank is visible in both images of any frame");
    }
    RCM_RETURN_IF_ERROR(
        WriteCorrespondenceCsv((root / "matches.csv").string(), matches));
  }
  // The housing is part of what a user knows of the rig: thick ports are
  // written as port blocks, so that rcm estimate models them.
  StereoRig rig = simulator->rig();
  const SequenceOptions& sequence = simulator->options();
  if (!sequence.left_port.IsThin() || !sequence.right_port.IsThin()) {
    StatusOr<StereoRig> with_ports =
        rig.WithPorts(sequence.left_port, sequence.right_port);
    if (!with_ports.ok()) return with_ports.status();
    rig = std::move(with_ports).value();
  }
  RCM_RETURN_IF_ERROR(WriteCamchain((root / "camchain.yaml").string(),
                                    CamchainFromStereoRig(rig)));
  if (sequence.board) {
    RCM_RETURN_IF_ERROR(WriteFileAtomically((root / "board.csv").string(),
                                            FormatBoardCsv(*simulator)));
  }
  return WriteFileAtomically((root / "truth.csv").string(),
                             FormatTruthCsv(*simulator));
}

}  // namespace rcm
