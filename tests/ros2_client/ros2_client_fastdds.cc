// ROS 2-style robot stack on Fast DDS's C++ API, with the classes fastddsgen
// generated from its own ROS 2 IDL (ros2_interfaces.idl, without
// -typeobject, as rmw_fastrtps announces no type object either), and
// /tf_static through DynamicTypes (fastddsgen refuses rosidl's
// geometry_msgs IDL: ros2_tf.idl says why; fastdds_tf_dynamic.h). See
// ros2_client_common.h for what it does.
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "fastdds_tf_dynamic.h"
#include "ros2_client_common.h"
#include "ros2_interfaces.h"
#include "ros2_interfacesPubSubTypes.h"

namespace {

using namespace ros2_client;
namespace fdds = eprosima::fastdds::dds;
using RC = eprosima::fastrtps::types::ReturnCode_t;
using sensor_msgs::msg::dds_::JointState_;
using trajectory_msgs::msg::dds_::JointTrajectory_;

template <class T>
T* Check(T* p, const char* what) {
  if (!p) {
    std::fprintf(stderr, "ros2_client_fastdds: cannot create the %s\n", what);
    std::exit(1);
  }
  return p;
}

// ROS 2's default QoS (rmw_qos_profile_default): reliable, volatile, keep
// last 10; DEADLINE and LIVELINESS lease left infinite (Fast DDS's defaults).
template <class Qos>
void Ros2Default(Qos* q) {
  q->reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  q->durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  q->history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  q->history().depth = 10;
}

void OnTrajectory(const JointTrajectory_& t) {
  std::vector<std::vector<double>> pos;
  std::vector<double> times;
  std::size_t with_velocities = 0;
  for (const auto& p : t.points_()) {
    pos.push_back(p.positions_());
    times.push_back(p.time_from_start_().sec_() + 1e-9 * p.time_from_start_().nanosec_());
    if (!p.velocities_().empty() && p.velocities_().size() == p.positions_().size()) ++with_velocities;
  }
  ReportTrajectory(t.header_().stamp_().sec_(), t.header_().stamp_().nanosec_(), t.joint_names_(), pos, times,
                   with_velocities);
}

// /tf_static as tf2's static listener: reliable, transient local, keep last 1.
fdds::DataReader* MakeTfReader(fdds::DomainParticipant* dp, fdds::Subscriber* sub, const std::string& topic,
                               const fdds::DataReaderQos& rq, const dyn::DynamicType_ptr& tf_type) {
  auto* tf_support = new dyn::DynamicPubSubType(tf_type);
  fdds::TypeSupport tf_ts(tf_support);
  tf_ts->auto_fill_type_information(false);
  tf_ts->auto_fill_type_object(false);
  tf_ts.register_type(dp);
  fdds::Topic* tf_topic = Check(dp->create_topic(Wire(topic), tf_ts.get_type_name(), fdds::TOPIC_QOS_DEFAULT),
                                "topic");
  fdds::DataReaderQos sq = rq;
  sq.durability().kind = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
  sq.history().depth = 1;
  return Check(sub->create_datareader(tf_topic, sq), "reader");
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const int rc = Parse(argc, argv, "Fast DDS", &o); rc >= 0) return rc;
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipant* dp = Check(factory->create_participant(o.domain, factory->get_default_participant_qos()),
                                      "participant");
  fdds::TypeSupport js_type(new sensor_msgs::msg::dds_::JointState_PubSubType());
  fdds::TypeSupport tr_type(new trajectory_msgs::msg::dds_::JointTrajectory_PubSubType());
  js_type.register_type(dp);
  tr_type.register_type(dp);
  fdds::Topic* js_topic = Check(dp->create_topic(Wire(o.joint_states_topic), js_type.get_type_name(),
                                                 fdds::TOPIC_QOS_DEFAULT), "topic");
  fdds::Topic* tr_topic = Check(dp->create_topic(Wire(o.trajectory_topic), tr_type.get_type_name(),
                                                 fdds::TOPIC_QOS_DEFAULT), "topic");
  fdds::Publisher* pub = Check(dp->create_publisher(fdds::PUBLISHER_QOS_DEFAULT), "publisher");
  fdds::Subscriber* sub = Check(dp->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT), "subscriber");
  fdds::DataWriterQos wq = pub->get_default_datawriter_qos();
  Ros2Default(&wq);
  fdds::DataReaderQos rq = sub->get_default_datareader_qos();
  Ros2Default(&rq);
  fdds::DataWriter* writer = Check(pub->create_datawriter(js_topic, wq), "writer");
  fdds::DataReader* reader = Check(sub->create_datareader(tr_topic, rq), "reader");
  fdds::DataReader* js_reader = nullptr;
  if (!o.read_joint_states_topic.empty()) {
    fdds::Topic* t = Check(dp->create_topic(Wire(o.read_joint_states_topic), js_type.get_type_name(),
                                            fdds::TOPIC_QOS_DEFAULT), "topic");
    js_reader = Check(sub->create_datareader(t, rq), "reader");
  }
  const int states_wanted = js_reader ? 3 : 0;
  const dyn::DynamicType_ptr tf_type = TfMessageType();
  fdds::DataReader* tf_reader = MakeTfReader(dp, sub, o.tf_static_topic, rq, tf_type);
  dyn::DynamicData* tf_data = dyn::DynamicDataFactory::get_instance()->create_data(tf_type);
  int transforms = 0;

  JointState_ js;
  js.name_() = JointNames(o.positions.size());
  js.position_() = o.positions;
  js.velocity_() = std::vector<double>(o.positions.size(), 0.0);
  std::printf("publishing %s\n", o.joint_states_topic.c_str());
  std::fflush(stdout);
  int trajectories = 0, states = 0;
  const auto period = std::chrono::duration<double>(1.0 / o.rate);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.timeout);
  JointTrajectory_ t;
  fdds::SampleInfo info;
  while (std::chrono::steady_clock::now() < end &&
         (trajectories < o.trajectories || transforms < 1 || states < states_wanted)) {
    Now(&js.header_().stamp_().sec_(), &js.header_().stamp_().nanosec_());
    writer->write(&js);
    while (reader->take_next_sample(&t, &info) == RC::RETCODE_OK) {
      if (!info.valid_data) continue;
      OnTrajectory(t);
      ++trajectories;
    }
    JointState_ other;
    while (js_reader && js_reader->take_next_sample(&other, &info) == RC::RETCODE_OK) {
      if (info.valid_data && states++ < states_wanted) ReportJointState(other.name_(), other.position_());
    }
    while (tf_reader->take_next_sample(tf_data, &info) == RC::RETCODE_OK) {
      if (!info.valid_data) continue;
      ForEachTransform(*tf_data, [&](const std::string& parent, const std::string& child, double x, double y,
                                     double z, double w) {
        ReportTransform(parent, child, x, y, z, w);
        ++transforms;
      });
    }
    std::this_thread::sleep_for(period);
  }
  std::printf("done trajectories=%d transforms=%d joint_states=%d\n", trajectories, transforms, states);
  dyn::DynamicDataFactory::get_instance()->delete_data(tf_data);
  dp->delete_contained_entities();
  factory->delete_participant(dp);
  return trajectories >= o.trajectories && transforms >= 1 && states >= states_wanted ? 0 : 1;
}
