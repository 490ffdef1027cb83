// tf2_msgs/TFMessage for the Fast DDS client, built at run time with Fast
// DDS's DynamicTypes from the same rosidl-style definition as ros2_tf.idl
// (member names with a trailing underscore): fastddsgen refuses that IDL
// (ros2_tf.idl says why), DynamicTypes take the names as strings. No type
// object or type information is announced, as rmw_fastrtps does.
#pragma once

#include <string>
#include <vector>

#include <fastrtps/types/DynamicData.h>
#include <fastrtps/types/DynamicDataFactory.h>
#include <fastrtps/types/DynamicPubSubType.h>
#include <fastrtps/types/DynamicTypeBuilder.h>
#include <fastrtps/types/DynamicTypeBuilderFactory.h>
#include <fastrtps/types/DynamicTypeBuilderPtr.h>

namespace ros2_client {

namespace dyn = eprosima::fastrtps::types;

// A struct type named `name` with `members` (name, type) in order.
inline dyn::DynamicType_ptr Struct(const std::string& name,
                                   const std::vector<std::pair<std::string, dyn::DynamicType_ptr>>& members) {
  dyn::DynamicTypeBuilder_ptr b(dyn::DynamicTypeBuilderFactory::get_instance()->create_struct_builder());
  for (std::size_t i = 0; i < members.size(); ++i) {
    b->add_member(static_cast<dyn::MemberId>(i), members[i].first, members[i].second);
  }
  b->set_name(name);
  return b->build();
}

/// tf2_msgs::msg::dds_::TFMessage_ as rosidl's DDS IDL writes it.
inline dyn::DynamicType_ptr TfMessageType() {
  auto* f = dyn::DynamicTypeBuilderFactory::get_instance();
  const auto f64 = f->create_float64_type();
  const auto time = Struct("builtin_interfaces::msg::dds_::Time_",
                           {{"sec_", f->create_int32_type()}, {"nanosec_", f->create_uint32_type()}});
  const auto header = Struct("std_msgs::msg::dds_::Header_",
                             {{"stamp_", time}, {"frame_id_", f->create_string_type(dyn::BOUND_UNLIMITED)}});
  const auto vector3 = Struct("geometry_msgs::msg::dds_::Vector3_", {{"x_", f64}, {"y_", f64}, {"z_", f64}});
  const auto quaternion =
      Struct("geometry_msgs::msg::dds_::Quaternion_", {{"x_", f64}, {"y_", f64}, {"z_", f64}, {"w_", f64}});
  const auto transform =
      Struct("geometry_msgs::msg::dds_::Transform_", {{"translation_", vector3}, {"rotation_", quaternion}});
  const auto stamped = Struct("geometry_msgs::msg::dds_::TransformStamped_",
                              {{"header_", header},
                               {"child_frame_id_", f->create_string_type(dyn::BOUND_UNLIMITED)},
                               {"transform_", transform}});
  dyn::DynamicTypeBuilder_ptr seq(f->create_sequence_builder(stamped, dyn::BOUND_UNLIMITED));
  return Struct("tf2_msgs::msg::dds_::TFMessage_", {{"transforms_", seq->build()}});
}

/// Calls `report(parent, child, tx, ty, tz, qw)` for every transform of `m`.
template <class Report>
void ForEachTransform(dyn::DynamicData& m, Report report) {
  dyn::DynamicData* transforms = m.loan_value(0);
  if (!transforms) return;
  for (uint32_t i = 0; i < transforms->get_item_count(); ++i) {
    dyn::DynamicData* t = transforms->loan_value(i);
    if (!t) continue;
    dyn::DynamicData* header = t->loan_value(0);
    dyn::DynamicData* transform = t->loan_value(2);
    dyn::DynamicData* translation = transform ? transform->loan_value(0) : nullptr;
    dyn::DynamicData* rotation = transform ? transform->loan_value(1) : nullptr;
    if (header && translation && rotation) {
      report(header->get_string_value(1), t->get_string_value(1), translation->get_float64_value(0),
             translation->get_float64_value(1), translation->get_float64_value(2), rotation->get_float64_value(3));
    }
    if (rotation) transform->return_loaned_value(rotation);
    if (translation) transform->return_loaned_value(translation);
    if (transform) t->return_loaned_value(transform);
    if (header) t->return_loaned_value(header);
    transforms->return_loaned_value(t);
  }
  m.return_loaned_value(transforms);
}

}  // namespace ros2_client
