// The test process's own end of a cell: a DDS participant on the given
// vendor and domain and a framework Node on it, publishing no diagnostics of
// its own (so tests see only the services' diagnostics).
#pragma once

#include <memory>
#include <string>

#include "iplan/dds/participant.h"
#include "iplan/framework/node.h"

namespace iplan::testing {

struct TestNode {
  /// With a DDS Security keystore `security_dir` the participant
  /// authenticates as enclave `enclave` and takes its name.
  TestNode(const std::string& name, dds::Vendor vendor, int domain, const std::string& security_dir = "",
           const std::string& enclave = "iplan-observer") {
    dds::ParticipantOptions o;
    o.vendor = vendor;
    o.domain_id = domain;
    o.name = security_dir.empty() ? name : enclave;
    o.security_dir = security_dir;
    participant = dds::Participant::Create(o);
    framework::NodeOptions no;
    no.diagnostics_period = 0;
    node = std::make_unique<framework::Node>(name, *participant, no);
  }
  // Declared in this order so the node goes before its participant.
  std::unique_ptr<dds::Participant> participant;
  std::unique_ptr<framework::Node> node;
};

}  // namespace iplan::testing
