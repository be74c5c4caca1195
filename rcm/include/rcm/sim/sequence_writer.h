// Writes a simulated sequence (sequence_simulator.h) as a folder that the
// rest of the toolkit, and any other tool, can read:
//
//   left/000000.png ...   8-bit mono images of cam0 (when rendered)
//   right/000000.png ...  8-bit mono images of cam1, same names
//   matches.csv           exact (or noisy) correspondences of all frames,
//                         `frame,xl,yl,xr,yr,t` (when matches are sampled)
//   camchain.yaml         the in-air calibration (Kalibr camchain), with
//                         port blocks when the ports are thick: the
//                         nominal rig, without the extrinsic drift
//   board.csv             with a board, one row per frame:
//                         frame,t,tx,ty,tz,qx,qy,qz,qw,visible_left,
//                         visible_right with (t, q) the pose
//                         cam0_from_target (rcm::calib's target frame)
//                         and 1/0 whether each camera sees every inner
//                         corner
//   truth.csv             one row per frame: frame,t,n,tx,ty,tz,qx,qy,qz,qw
//                         with n the medium and (t, q) the pose
//                         world_from_cam0 (cam0's position in the world
//                         and its orientation, Hamilton quaternion)
//
// truth.csv is written last: a folder without it is incomplete (a run that
// failed or was interrupted). Every file is written atomically.
#ifndef RCM_SIM_SEQUENCE_WRITER_H_
#define RCM_SIM_SEQUENCE_WRITER_H_

#include <functional>
#include <string>

#include "rcm/sim/sequence_simulator.h"
#include "rcm/util/status.h"

namespace rcm {

struct SequenceWriterOptions {
  // Replace the files of an earlier sequence in the folder (its frames,
  // matches, camchain, board and truth). Without it, a folder that already
  // holds any of them is refused.
  bool overwrite = false;
  // Called after each frame is written with (frames done, total).
  std::function<void(int, int)> progress;
};

// The file name of frame `index` in left/ and right/: 000042.png.
std::string SequenceImageName(int index);

// The truth.csv text of a simulator's frames.
std::string FormatTruthCsv(const SequenceSimulator& simulator);
// The board.csv text (the header alone without a board).
std::string FormatBoardCsv(const SequenceSimulator& simulator);

// Simulates every frame and writes the folder (created if missing). Fails
// with one line when the folder cannot be created or written, or already
// holds a sequence and overwrite is false.
Status WriteSequence(const std::string& folder, SequenceSimulator* simulator,
                     const SequenceWriterOptions& options);

}  // namespace rcm

#endif  // RCM_SIM_SEQUENCE_WRITER_H_
