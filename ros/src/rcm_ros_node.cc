// rcm_ros_node: rcm live on the robot, a ROS1 node between the stereo
// camera driver and the VIO. A thin adapter over rcm::LivePipeline
// (rcm/live/live_pipeline.h), which does all the work and knows nothing of
// ROS; a ROS 2 node would be another adapter of the same class.
//
//   subscribes  left/image_raw, right/image_raw   (relative: remap them;
//               raw or compressed through image_transport's ~image_transport
//               parameter), paired by header stamp within ~sync_tolerance
//   publishes   ~refractive_index                 rcm_ros/RefractiveIndex
//               ~left/image_rect, ~right/image_rect  the corrected pair,
//               ~left/camera_info, ~right/camera_info  stamped as the input
//                 (rectified: both in the left's frame_id, as
//                 stereo_image_proc expects)
//               /diagnostics                      rate, drops, state
//   services    ~reset (rcm_ros/Reset), ~hold (std_srvs/SetBool)
//
// Threads. The ROS callbacks (one spinner thread) only pair the images and
// put the pair in a LatestSlot, a queue of one: when the worker is still
// busy with the last pair, the new one replaces the one waiting (counted as
// a drop), so the node never queues without bound and always works on the
// latest pair. The worker thread owns the pipeline; services hand it their
// request and wait for it to be applied.
//
// Bad input never stops the node: a refused pair (wrong size or encoding,
// a blank frame), a pair without an estimate (too few matches, n pinned at
// its bound by a stale calibration), images that never pair, a camera that
// stops: a warning throttled to one per ~warn_period per cause, nothing
// published from that data. A bad ~calib or parameter: one line, exit 1.
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <std_srvs/SetBool.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <future>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rcm/camera/virtual_pinhole_remap.h"
#include "rcm/io/corrected_rig_files.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/live/latest_slot.h"
#include "rcm/live/live_pipeline.h"
#include "rcm/stereo/virtual_pinhole_rig.h"
#include "rcm/util/heap_padding.h"
#include "rcm_ros/RefractiveIndex.h"
#include "rcm_ros/Reset.h"
#include "ros_image_message.h"

namespace rcm {
namespace {

using ImageConstPtr = sensor_msgs::ImageConstPtr;
using SyncPolicy =
    message_filters::sync_policies::ApproximateTime<sensor_msgs::Image,
                                                    sensor_msgs::Image>;

struct StereoPair {
  ImageConstPtr left;
  ImageConstPtr right;
};

// Images the other camera must give after a camera's last one before that
// camera counts as stopped.
constexpr int64_t kMinImagesOfTheOther = 3;

struct NodeOptions {
  std::string calib;
  LivePipelineOptions pipeline;
  double sync_tolerance = 0.005;  // [s] of header stamps
  double warn_period = 5.0;       // [s] between warnings of one cause
  double stale_after = 1.0;       // [s] of silence of one camera
  bool hold = false;
};

// A parameter of the private namespace; its default when absent.
template <typename T>
T Param(const ros::NodeHandle& nh, const std::string& name, T fallback) {
  T value = fallback;
  nh.param(name, value, fallback);
  return value;
}

// The node's options from its private parameters, or the first bad one.
StatusOr<NodeOptions> ReadOptions(const ros::NodeHandle& nh) {
  NodeOptions options;
  options.calib = Param<std::string>(nh, "calib", "");
  if (options.calib.empty()) {
    return Status::Error(
        "~calib is not set: give the camchain (camchain.yaml) or the two "
        "camera_info files (left.yaml,right.yaml) of the rig calibrated in "
        "air");
  }
  LivePipelineOptions& p = options.pipeline;
  p.window.SetWindowFrames(Param(nh, "window", p.window.window_frames));
  p.window.change_threshold =
      Param(nh, "change_threshold", p.window.change_threshold);
  p.window.confirm_frames =
      Param(nh, "confirm_frames", p.window.confirm_frames);
  p.front_end.features.max_features =
      Param(nh, "features", p.front_end.features.max_features);
  p.front_end.search_range.min =
      Param(nh, "search_min", p.front_end.search_range.min);
  p.front_end.search_range.max =
      Param(nh, "search_max", p.front_end.search_range.max);
  // ~max_matches: the name of 0.2.0's parameter, still read.
  if (nh.hasParam("max_matches") && !nh.hasParam("window_matches")) {
    ROS_WARN("~max_matches is now ~window_matches; read as such");
    p.window_matches = Param(nh, "max_matches", p.window_matches);
  }
  p.window_matches = Param(nh, "window_matches", p.window_matches);
  p.map_update_threshold =
      Param(nh, "map_update_threshold", p.map_update_threshold);
  p.map_update_sigmas = Param(nh, "map_update_sigmas", p.map_update_sigmas);
  p.initial_n = Param(nh, "initial_n", p.initial_n);
  p.min_contrast = Param(nh, "min_contrast", p.min_contrast);
  p.correction.rectify = Param(nh, "rectify", p.correction.rectify);
  const std::string fit =
      Param<std::string>(nh, "fit", VirtualPinholeFitName(p.correction.fit));
  const std::optional<VirtualPinholeFit> parsed =
      VirtualPinholeFitFromName(fit);
  if (!parsed) {
    return Status::Error("~fit '" + fit +
                         "' is not one of virtual-pinhole, no-border, full");
  }
  p.correction.fit = *parsed;
  options.sync_tolerance = Param(nh, "sync_tolerance", options.sync_tolerance);
  options.warn_period = Param(nh, "warn_period", options.warn_period);
  options.stale_after = Param(nh, "stale_after", options.stale_after);
  options.hold = Param(nh, "hold", options.hold);
  if (!(options.sync_tolerance >= 0.0) ||
      !std::isfinite(options.sync_tolerance)) {
    return Status::Error("~sync_tolerance must be >= 0 seconds");
  }
  if (!(options.warn_period > 0.0) || !(options.stale_after > 0.0)) {
    return Status::Error("~warn_period and ~stale_after must be > 0 seconds");
  }
  if (Status status = p.Check(); !status.ok()) {
    return Status::Error("bad parameter: " + status.message());
  }
  return options;
}

// One warning per cause and period (ROS_WARN_THROTTLE keys on the call
// site; the causes here share one).
class ThrottledWarning {
 public:
  explicit ThrottledWarning(double period) : period_(period) {}
  void Warn(const std::string& cause, const std::string& text) {
    const double now = ros::WallTime::now().toSec();
    std::lock_guard<std::mutex> lock(mutex_);
    double& last = last_[cause];
    if (last != 0.0 && now - last < period_) return;
    last = now;
    ROS_WARN("%s", text.c_str());
  }

 private:
  double period_;
  std::mutex mutex_;
  std::map<std::string, double> last_;
};

class RcmRosNode {
 public:
  RcmRosNode(ros::NodeHandle nh, ros::NodeHandle private_nh,
             NodeOptions options, std::unique_ptr<LivePipeline> pipeline)
      : nh_(nh),
        private_nh_(private_nh),
        options_(std::move(options)),
        pipeline_(std::move(pipeline)),
        warnings_(options_.warn_period),
        it_(nh_),
        private_it_(private_nh_),
        left_sub_(it_, "left/image_raw", 2),
        right_sub_(it_, "right/image_raw", 2),
        sync_(SyncPolicy(10), left_sub_, right_sub_) {
    pipeline_->SetHold(options_.hold);
    sync_.setMaxIntervalDuration(ros::Duration(options_.sync_tolerance));
    sync_.registerCallback(&RcmRosNode::OnPair, this);
    left_sub_.registerCallback(&RcmRosNode::OnLeft, this);
    right_sub_.registerCallback(&RcmRosNode::OnRight, this);
    index_pub_ =
        private_nh_.advertise<rcm_ros::RefractiveIndex>("refractive_index", 10);
    left_pub_ = private_it_.advertiseCamera("left/image_rect", 2);
    right_pub_ = private_it_.advertiseCamera("right/image_rect", 2);
    reset_srv_ =
        private_nh_.advertiseService("reset", &RcmRosNode::OnReset, this);
    hold_srv_ = private_nh_.advertiseService("hold", &RcmRosNode::OnHold, this);
    diagnostics_.setHardwareID("rcm");
    diagnostics_.add("refractive index", this, &RcmRosNode::Diagnose);
    watchdog_ = nh_.createWallTimer(ros::WallDuration(0.5),
                                    &RcmRosNode::OnWatchdog, this);
    worker_ = std::thread(&RcmRosNode::Work, this);
  }

  ~RcmRosNode() {
    stop_ = true;
    slot_.Close();
    if (worker_.joinable()) worker_.join();
    pipeline_->WaitForMaps();
  }

 private:
  // --- ROS callbacks (spinner thread) --------------------------------------
  void OnLeft(const ImageConstPtr&) {
    last_left_ = Now();
    ++left_at_last_right_;
    right_at_last_left_ = 0;
  }
  void OnRight(const ImageConstPtr&) {
    last_right_ = Now();
    ++right_at_last_left_;
    left_at_last_right_ = 0;
  }

  void OnPair(const ImageConstPtr& left, const ImageConstPtr& right) {
    last_pair_ = Now();
    ++num_pairs_;
    slot_.Put(StereoPair{left, right});
  }

  bool OnReset(rcm_ros::Reset::Request& request,
               rcm_ros::Reset::Response& response) {
    std::optional<double> n;
    if (request.n != 0.0) n = request.n;
    const Status status = Apply([this, n] { return pipeline_->Reset(n); });
    response.success = status.ok();
    response.message = status.ok() ? "reset" : status.message();
    return true;
  }

  bool OnHold(std_srvs::SetBool::Request& request,
              std_srvs::SetBool::Response& response) {
    const bool hold = request.data;
    const Status status = Apply([this, hold] {
      pipeline_->SetHold(hold);
      return Status::Ok();
    });
    response.success = status.ok();
    response.message = hold ? "held" : "released";
    return true;
  }

  // Pairs that never sync, a camera that stops.
  void OnWatchdog(const ros::WallTimerEvent&) {
    diagnostics_.update();
    const double now = Now();
    const double left = last_left_, right = last_right_, pair = last_pair_;
    const double stale = options_.stale_after;
    if (left > 0.0 && right > 0.0 && now - left < stale &&
        now - right < stale && now - pair > stale) {
      warnings_.Warn("sync",
                     "rcm_ros_node: left and right images arrive but "
                     "none pair within ~sync_tolerance (" +
                         std::to_string(options_.sync_tolerance) +
                         " s); nothing published");
    }
    // A camera stopped: silent for stale_after while the other gave at
    // least kMinImagesOfTheOther images since its last (not a pause of
    // both, where one resumes a moment before the other).
    if (left > 0.0 && now - left > stale && right > 0.0 &&
        now - right < stale && right_at_last_left_ >= kMinImagesOfTheOther) {
      warnings_.Warn("left",
                     "rcm_ros_node: the left camera stopped (no image "
                     "for " +
                         Seconds(now - left) + "); nothing published");
    }
    if (right > 0.0 && now - right > stale && left > 0.0 &&
        now - left < stale && left_at_last_right_ >= kMinImagesOfTheOther) {
      warnings_.Warn("right",
                     "rcm_ros_node: the right camera stopped (no "
                     "image for " +
                         Seconds(now - right) + "); nothing published");
    }
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
    std::lock_guard<std::mutex> lock(state_mutex_);
    status.summary(state_ok_ ? diagnostic_msgs::DiagnosticStatus::OK
                             : diagnostic_msgs::DiagnosticStatus::WARN,
                   state_);
    status.add("pairs received", static_cast<int64_t>(num_pairs_));
    status.add("pairs processed", num_processed_);
    status.add("pairs dropped (worker busy)", slot_.num_dropped());
    status.add("pairs refused (bad input)", pipeline_refused_);
    status.add("pairs without estimate", num_no_estimate_);
    status.add("processing rate [Hz]", rate_hz_);
    status.add("n", last_n_);
    status.add("sigma_n", last_sigma_);
    status.add("maps n", maps_n_);
    status.add("hold", held_);
  }

  // --- worker thread
  // ---------------------------------------------------------- Runs `command`
  // on the worker thread, waiting up to 5 s.
  Status Apply(std::function<Status()> command) {
    std::packaged_task<Status()> task(std::move(command));
    std::future<Status> done = task.get_future();
    {
      std::lock_guard<std::mutex> lock(command_mutex_);
      commands_.push_back(std::move(task));
    }
    if (done.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
      return Status::Error("the worker did not answer within 5 s");
    }
    return done.get();
  }

  void RunCommands() {
    std::vector<std::packaged_task<Status()>> commands;
    {
      std::lock_guard<std::mutex> lock(command_mutex_);
      commands.swap(commands_);
    }
    for (auto& command : commands) command();
  }

  void Work() {
    double last_done = 0.0;
    while (!stop_) {
      RunCommands();
      std::optional<StereoPair> pair =
          slot_.Take(std::chrono::milliseconds(50));
      RunCommands();
      if (!pair) continue;
      Process(*pair);
      const double now = Now();
      if (last_done > 0.0) {
        const double hz = 1.0 / std::max(now - last_done, 1e-6);
        rate_hz_ = rate_hz_ == 0.0 ? hz : 0.9 * rate_hz_ + 0.1 * hz;
      }
      last_done = now;
    }
  }

  void SetState(bool ok, const std::string& state) {
    std::lock_guard<std::mutex> lock(state_mutex_);
    state_ok_ = ok;
    state_ = state;
  }

  void Process(const StereoPair& pair) {
    cv::Mat images[2];
    for (int c = 0; c < 2; ++c) {
      const sensor_msgs::Image& message = c == 0 ? *pair.left : *pair.right;
      StatusOr<cv::Mat> image = DecodeImage(message);
      if (!image.ok()) {
        ++pipeline_refused_;
        SetState(false, "bad input");
        warnings_.Warn("decode", std::string("rcm_ros_node: ") +
                                     (c == 0 ? "left" : "right") + " image (" +
                                     message.encoding + ", " +
                                     std::to_string(message.width) + "x" +
                                     std::to_string(message.height) +
                                     ") refused: " + image.status().message() +
                                     "; nothing published");
        return;
      }
      images[c] = std::move(image).value();
    }
    const double stamp = pair.left->header.stamp.toSec();
    StatusOr<LiveFrame> result =
        pipeline_->Process(images[0], images[1], stamp);
    if (!result.ok()) {
      ++pipeline_refused_;
      SetState(false, "bad input");
      warnings_.Warn("refused", "rcm_ros_node: pair at " +
                                    std::to_string(stamp) +
                                    " refused: " + result.status().message() +
                                    "; nothing published");
      return;
    }
    ++num_processed_;
    const LiveFrame& frame = result.value();
    held_ = frame.held;
    maps_n_ = frame.maps_n;
    rcm_ros::RefractiveIndex index;
    index.header = pair.left->header;
    index.num_matches = static_cast<uint32_t>(frame.num_matches);
    index.num_estimated = static_cast<uint32_t>(frame.num_estimated);
    index.held = frame.held;
    index.maps_n = frame.maps_n;
    index.medium_switch = frame.medium_switch.has_value();
    index.switch_from = frame.medium_switch
                            ? frame.medium_switch->n_before
                            : std::numeric_limits<double>::quiet_NaN();
    if (frame.estimate.ok()) {
      index.valid = true;
      index.n = frame.estimate.value().n;
      index.sigma_n = frame.estimate.value().sigma_n;
      index.status = "ok";
      last_n_ = index.n;
      last_sigma_ = index.sigma_n;
      SetState(true, "estimating");
      // The library's warnings (a stale calibration, ...), each throttled
      // by its own cause: the words before its first ':' or '('.
      for (const std::string& warning : frame.warnings) {
        warnings_.Warn(warning.substr(0, warning.find_first_of(":(")),
                       "rcm_ros_node: " + warning);
      }
    } else {
      // No estimate is never a number: valid false, n NaN, the reason.
      ++num_no_estimate_;
      index.valid = false;
      index.n = std::numeric_limits<double>::quiet_NaN();
      index.sigma_n = std::numeric_limits<double>::quiet_NaN();
      index.status = frame.estimate.status().message();
      SetState(false, "no estimate");
      warnings_.Warn("estimate",
                     "rcm_ros_node: no estimate of n: " + index.status);
    }
    index_pub_.publish(index);
    if (frame.medium_switch) {
      ROS_INFO("rcm_ros_node: the medium changed: n %.4f -> %.4f",
               frame.medium_switch->n_before, frame.medium_switch->n_after);
    }
    PublishCorrected(pair, frame);
  }

  void PublishCorrected(const StereoPair& pair, const LiveFrame& frame) {
    if (left_pub_.getNumSubscribers() == 0 &&
        right_pub_.getNumSubscribers() == 0) {
      return;
    }
    if (frame.corrected != infos_for_) {
      infos_for_ = frame.corrected;
      const auto [left, right] =
          CorrectedCameraInfos(*frame.corrected, "rcm_left", "rcm_right");
      left_info_ = CameraInfoMessage(left);
      right_info_ = CameraInfoMessage(right);
    }
    const std::string encoding =
        frame.left_corrected.channels() == 1 ? "mono8" : "bgr8";
    const cv::Mat* images[2] = {&frame.left_corrected, &frame.right_corrected};
    const ImageConstPtr inputs[2] = {pair.left, pair.right};
    sensor_msgs::CameraInfo* infos[2] = {&left_info_, &right_info_};
    image_transport::CameraPublisher* pubs[2] = {&left_pub_, &right_pub_};
    for (int c = 0; c < 2; ++c) {
      std_msgs::Header header = inputs[c]->header;
      // A rectified pair is one camera model in ROS (image_geometry's
      // StereoCameraModel, stereo_image_proc): both images in the left
      // rectified frame, the baseline in the right's P.
      if (options_.pipeline.correction.rectify) {
        header.frame_id = inputs[0]->header.frame_id;
      }
      sensor_msgs::ImagePtr image =
          cv_bridge::CvImage(header, encoding, *images[c]).toImageMsg();
      infos[c]->header = header;
      pubs[c]->publish(*image, *infos[c]);
    }
  }

  static double Now() { return ros::WallTime::now().toSec(); }
  static std::string Seconds(double s) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.1f s", s);
    return text;
  }

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  NodeOptions options_;
  std::unique_ptr<LivePipeline> pipeline_;
  ThrottledWarning warnings_;
  image_transport::ImageTransport it_;
  image_transport::ImageTransport private_it_;
  image_transport::SubscriberFilter left_sub_;
  image_transport::SubscriberFilter right_sub_;
  message_filters::Synchronizer<SyncPolicy> sync_;
  ros::Publisher index_pub_;
  image_transport::CameraPublisher left_pub_;
  image_transport::CameraPublisher right_pub_;
  ros::ServiceServer reset_srv_;
  ros::ServiceServer hold_srv_;
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer watchdog_;

  LatestSlot<StereoPair> slot_;
  std::mutex command_mutex_;
  std::vector<std::packaged_task<Status()>> commands_;
  std::thread worker_;
  std::atomic<bool> stop_{false};

  std::atomic<double> last_left_{0.0};
  std::atomic<double> last_right_{0.0};
  std::atomic<double> last_pair_{0.0};
  // Images of one camera since the other's last image.
  std::atomic<int64_t> left_at_last_right_{0};
  std::atomic<int64_t> right_at_last_left_{0};
  std::atomic<int64_t> num_pairs_{0};
  std::atomic<int64_t> num_processed_{0};
  std::atomic<int64_t> pipeline_refused_{0};
  std::atomic<int64_t> num_no_estimate_{0};
  std::atomic<double> rate_hz_{0.0};
  std::atomic<double> last_n_{std::numeric_limits<double>::quiet_NaN()};
  std::atomic<double> last_sigma_{std::numeric_limits<double>::quiet_NaN()};
  std::atomic<double> maps_n_{1.0};
  std::atomic<bool> held_{false};
  std::mutex state_mutex_;
  bool state_ok_ = true;
  std::string state_ = "waiting for images";

  std::shared_ptr<const VirtualPinholeRig> infos_for_;
  sensor_msgs::CameraInfo left_info_;
  sensor_msgs::CameraInfo right_info_;
};

}  // namespace
}  // namespace rcm

int main(int argc, char** argv) {
  // Each pair's buffers reuse the heap instead of faulting pages in anew
  // (rcm/util/heap_padding.h).
  rcm::PadHeapGrowth();
  ros::init(argc, argv, "rcm");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  const rcm::StatusOr<rcm::NodeOptions> options = rcm::ReadOptions(private_nh);
  if (!options.ok()) {
    std::fprintf(stderr, "rcm_ros_node: %s\n",
                 options.status().message().c_str());
    return 1;
  }
  const rcm::StatusOr<rcm::StereoRig> rig = rcm::ReadStereoRig(options->calib);
  if (!rig.ok()) {
    std::fprintf(stderr, "rcm_ros_node: ~calib %s: %s\n",
                 options->calib.c_str(), rig.status().message().c_str());
    return 1;
  }
  rcm::StatusOr<std::unique_ptr<rcm::LivePipeline>> pipeline =
      rcm::LivePipeline::Create(rig.value(), options->pipeline);
  if (!pipeline.ok()) {
    std::fprintf(stderr, "rcm_ros_node: %s\n",
                 pipeline.status().message().c_str());
    return 1;
  }
  ROS_INFO(
      "rcm_ros_node: rig %s, %dx%d; maps for n %.4f; waiting for "
      "%s and %s",
      options->calib.c_str(), rig->left().width(), rig->left().height(),
      options->pipeline.initial_n, nh.resolveName("left/image_raw").c_str(),
      nh.resolveName("right/image_raw").c_str());
  {
    rcm::RcmRosNode node(nh, private_nh, options.value(),
                         std::move(pipeline).value());
    ros::spin();
  }
  return 0;
}
