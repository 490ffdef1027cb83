// ROS 2-style robot stack on Cyclone DDS's C API, with types idlc generated
// from its own ROS 2 IDL (ros2_interfaces.idl) WITH XTypes type information
// (idlc's default), as a Cyclone application built from rosidl's IDL would.
// See ros2_client_common.h for what it does.
#include <dds/dds.h>

#include <thread>

#include "ros2_client_common.h"
#include "ros2_interfaces.h"
#include "ros2_tf.h"

namespace {

using namespace ros2_client;

// ROS 2's default QoS (rmw_qos_profile_default): reliable, volatile, keep
// last 10; DEADLINE and LIVELINESS lease left infinite.
dds_qos_t* DefaultQos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
  return q;
}

// tf2's static listener: reliable, transient local, keep last 1.
dds_qos_t* StaticQos() {
  dds_qos_t* q = DefaultQos();
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  return q;
}

dds_entity_t Check(dds_entity_t e, const char* what) {
  if (e < 0) {
    std::fprintf(stderr, "ros2_client_cyclone: %s: %s\n", what, dds_strretcode(e));
    std::exit(1);
  }
  return e;
}

void OnTrajectory(const trajectory_msgs_msg_dds__JointTrajectory_& t) {
  std::vector<std::string> joints(t.joint_names_._buffer, t.joint_names_._buffer + t.joint_names_._length);
  std::vector<std::vector<double>> pos;
  std::vector<double> times;
  std::size_t with_velocities = 0;
  for (uint32_t i = 0; i < t.points_._length; ++i) {
    const auto& p = t.points_._buffer[i];
    pos.emplace_back(p.positions_._buffer, p.positions_._buffer + p.positions_._length);
    times.push_back(p.time_from_start_.sec_ + 1e-9 * p.time_from_start_.nanosec_);
    if (p.velocities_._length == p.positions_._length && p.velocities_._length > 0) ++with_velocities;
  }
  ReportTrajectory(t.header_.stamp_.sec_, t.header_.stamp_.nanosec_, joints, pos, times, with_velocities);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const int rc = Parse(argc, argv, "Cyclone DDS", &o); rc >= 0) return rc;
  const dds_entity_t dp = Check(dds_create_participant(static_cast<dds_domainid_t>(o.domain), nullptr, nullptr), "participant");
  const dds_entity_t js_topic = Check(dds_create_topic(dp, &sensor_msgs_msg_dds__JointState__desc,
                                                       Wire(o.joint_states_topic).c_str(), nullptr, nullptr), "topic");
  const dds_entity_t tr_topic = Check(dds_create_topic(dp, &trajectory_msgs_msg_dds__JointTrajectory__desc,
                                                       Wire(o.trajectory_topic).c_str(), nullptr, nullptr), "topic");
  const dds_entity_t tf_topic = Check(dds_create_topic(dp, &tf2_msgs_msg_dds__TFMessage__desc,
                                                       Wire(o.tf_static_topic).c_str(), nullptr, nullptr), "topic");
  dds_qos_t* def = DefaultQos();
  dds_qos_t* stat = StaticQos();
  const dds_entity_t writer = Check(dds_create_writer(dp, js_topic, def, nullptr), "writer");
  const dds_entity_t tr_reader = Check(dds_create_reader(dp, tr_topic, def, nullptr), "reader");
  const dds_entity_t tf_reader = Check(dds_create_reader(dp, tf_topic, stat, nullptr), "reader");
  dds_entity_t js_reader = 0;
  if (!o.read_joint_states_topic.empty()) {
    const dds_entity_t t = Check(dds_create_topic(dp, &sensor_msgs_msg_dds__JointState__desc,
                                                  Wire(o.read_joint_states_topic).c_str(), nullptr, nullptr), "topic");
    js_reader = Check(dds_create_reader(dp, t, def, nullptr), "reader");
  }

  dds_delete_qos(def);
  dds_delete_qos(stat);
  std::vector<std::string> names = JointNames(o.positions.size());
  std::vector<char*> name_ptrs;
  for (auto& n : names) name_ptrs.push_back(n.data());
  std::vector<double> zeros(o.positions.size(), 0.0);
  sensor_msgs_msg_dds__JointState_ js{};
  js.header_.frame_id_ = const_cast<char*>("");
  js.name_ = {static_cast<uint32_t>(names.size()), static_cast<uint32_t>(names.size()), name_ptrs.data(), false};
  js.position_ = {static_cast<uint32_t>(o.positions.size()), static_cast<uint32_t>(o.positions.size()), o.positions.data(), false};
  js.velocity_ = {static_cast<uint32_t>(zeros.size()), static_cast<uint32_t>(zeros.size()), zeros.data(), false};

  std::printf("publishing %s\n", o.joint_states_topic.c_str());
  std::fflush(stdout);
  int trajectories = 0, transforms = 0, states = 0;
  const int states_wanted = js_reader ? 3 : 0;
  const auto period = std::chrono::duration<double>(1.0 / o.rate);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.timeout);
  while (std::chrono::steady_clock::now() < end &&
         (trajectories < o.trajectories || transforms < 1 || states < states_wanted)) {
    Now(&js.header_.stamp_.sec_, &js.header_.stamp_.nanosec_);
    dds_write(writer, &js);
    void* samples[1] = {nullptr};
    dds_sample_info_t info;
    while (dds_take(tr_reader, samples, &info, 1, 1) > 0) {
      if (info.valid_data) {
        OnTrajectory(*static_cast<trajectory_msgs_msg_dds__JointTrajectory_*>(samples[0]));
        ++trajectories;
      }
      dds_return_loan(tr_reader, samples, 1);
    }
    while (dds_take(tf_reader, samples, &info, 1, 1) > 0) {
      if (info.valid_data) {
        const auto& m = *static_cast<tf2_msgs_msg_dds__TFMessage_*>(samples[0]);
        for (uint32_t i = 0; i < m.transforms_._length; ++i) {
          const auto& t = m.transforms_._buffer[i];
          ReportTransform(t.header_.frame_id_, t.child_frame_id_, t.transform_.translation_.x_,
                          t.transform_.translation_.y_, t.transform_.translation_.z_, t.transform_.rotation_.w_);
          ++transforms;
        }
      }
      dds_return_loan(tf_reader, samples, 1);
    }
    while (js_reader && dds_take(js_reader, samples, &info, 1, 1) > 0) {
      if (info.valid_data && states++ < states_wanted) {
        const auto& m = *static_cast<sensor_msgs_msg_dds__JointState_*>(samples[0]);
        ReportJointState(std::vector<std::string>(m.name_._buffer, m.name_._buffer + m.name_._length),
                         std::vector<double>(m.position_._buffer, m.position_._buffer + m.position_._length));
      }
      dds_return_loan(js_reader, samples, 1);
    }
    std::this_thread::sleep_for(period);
  }
  std::printf("done trajectories=%d transforms=%d joint_states=%d\n", trajectories, transforms, states);
  dds_delete(dp);
  return trajectories >= o.trajectories && transforms >= 1 && states >= states_wanted ? 0 : 1;
}
