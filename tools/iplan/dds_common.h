// Options and helpers shared by the iplan subcommands that talk DDS.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "iplan/dds/participant.h"
#include "iplan/framework/enclaves.h"
#include "iplan/framework/topics.h"

namespace iplan::cli {

struct DdsOptions {
  std::string vendor;  ///< empty: $IPLAN_DDS or cyclonedds
  int domain = -1;     ///< negative: $IPLAN_DOMAIN or 0
  std::string security;  ///< DDS Security keystore; empty: $IPLAN_SECURITY or none
  std::string enclave = framework::kObserverEnclave;  ///< with a keystore: whose identity
};

/// Adds --dds, --domain, --security and --enclave to a subcommand.
void AddDdsOptions(CLI::App* app, DdsOptions* o);

/// Creates the participant; throws std::runtime_error / invalid_argument.
/// With a keystore the participant authenticates as `o.enclave` and takes
/// its name (the name its writers announce), not `name`.
std::unique_ptr<dds::Participant> MakeParticipant(const DdsOptions& o, const std::string& name,
                                                  bool track_endpoints = false);

/// "rt/iplan/x", "/iplan/x" and "iplan/x" all name DDS topic "rt/iplan/x".
std::string DdsTopicName(const std::string& name);

/// The last `lines` lines of `text` (all of it when it has fewer), e.g. of a
/// service's stderr for an error message.
std::string Tail(const std::string& text, size_t lines);
/// "rt/iplan/x" -> "/iplan/x" (ROS 2 form); other names unchanged.
std::string RosTopicName(const std::string& dds_name);

/// The catalogue entry of a topic, if it is one of iplan's.
std::optional<framework::TopicDescription> FindCatalogueTopic(const std::string& dds_name);

}  // namespace iplan::cli
