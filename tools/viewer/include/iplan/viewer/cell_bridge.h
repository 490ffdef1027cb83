// The viewer's and the recorder's window on the cell: a DDS participant that
// subscribes to the cell's catalogue topics (common/framework topics.cc) and
// hands every message on as JSON (the generated reflection, as `iplan topic
// echo` prints it), plus two derived channels:
//   /iplan/viewer/scene  foxglove.SceneUpdate entities (SceneBuilder) from the
//                        checked joint states, skeletons, predictions,
//                        trajectories and collision risk;
//   /iplan/viewer/cell   {"alive": bool, "last_message_age_s": s,
//                        "alive_after_s": s, "status_period_s": s, ...} every
//                        `status_period`: alive while some cell topic
//                        delivered within `alive_after`. A client that gets
//                        the status late (a page that is behind) adds its
//                        delay to last_message_age_s (web/src/viewer.js).
// The scene's inputs come through a framework Node, so they pass the same
// writer and content checks as in a service (not the stamp order: a viewer
// draws late and reordered messages too); a message the scene cannot use is
// counted and logged by the node (rejected_inputs/scene).
// The bridge never writes to the cell (no diagnostics, no commands).
//
// Threading: construct, then call SpinOnce from one thread; the sink is
// called on that thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "iplan/dds/participant.h"
#include "iplan/viewer/scene_builder.h"

namespace iplan::viewer {

/// Names of the derived channels.
inline constexpr const char* kSceneTopic = "/iplan/viewer/scene";
inline constexpr const char* kCellTopic = "/iplan/viewer/cell";

struct BridgeChannel {
  std::string topic;        ///< ROS form, e.g. "/joint_states"
  std::string schema_name;  ///< ROS 2 form "pkg/msg/Type", or "foxglove.SceneUpdate"
  std::string schema;       ///< JSON Schema text
};

struct CellBridgeOptions {
  /// Topics to bridge (ROS or DDS form); empty: every catalogue topic.
  std::vector<std::string> topics;
  /// Folder of the Foxglove JSON schemas (web/dist/schemas); needed for the scene.
  std::string schema_dir;
  double robot_rate_hz = 30;       ///< most robot scene updates per second
  double prediction_rate_hz = 10;  ///< most prediction scene updates per second
  double alive_after = 1.0;        ///< s without any cell message: the cell is gone
  double status_period = 0.5;      ///< s between two /iplan/viewer/cell statuses
  std::size_t max_payload_bytes = 8u << 20;  ///< larger JSON messages are dropped (counted)
};

struct BridgeStats {
  uint64_t forwarded = 0;       ///< messages handed to the sink
  uint64_t skipped = 0;         ///< not converted: nobody wanted the channel
  uint64_t too_large = 0;
  uint64_t scene_rejected = 0;  ///< scene inputs the model could not use
  std::string last_scene_rejection;
};

class CellBridge {
 public:
  /// channel index (into channels()), log time (ns since the epoch), JSON text.
  using Sink = std::function<void(std::size_t, uint64_t, const std::string&)>;
  /// True when the channel has a consumer (default: always).
  using Wanted = std::function<bool(std::size_t)>;

  /// `scene`: draws the scene channel; nullopt: no scene channel.
  /// @throws std::invalid_argument for an unknown topic, std::runtime_error
  ///         for DDS errors or a missing schema file.
  CellBridge(dds::Participant& participant, std::optional<SceneBuilder> scene, CellBridgeOptions options, Sink sink,
             Wanted wanted = nullptr);
  ~CellBridge();

  const std::vector<BridgeChannel>& channels() const;
  /// Waits at most `max_wait` for messages and forwards what arrived.
  void SpinOnce(std::chrono::nanoseconds max_wait);
  BridgeStats stats() const;
  /// Messages forwarded per channel index.
  const std::vector<uint64_t>& counts() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// "sensor_msgs::msg::dds_::JointState_" -> "sensor_msgs/msg/JointState".
std::string RosTypeName(const std::string& dds_type);

}  // namespace iplan::viewer
