#include "dds_common.h"

#include "iplan/dds/security.h"

namespace iplan::cli {

void AddDdsOptions(CLI::App* app, DdsOptions* o) {
  app->add_option("--dds", o->vendor, "DDS vendor: cyclonedds or fastdds (default: $IPLAN_DDS, else cyclonedds)");
  app->add_option("--domain", o->domain, "DDS domain id 0-232 (default: $IPLAN_DOMAIN, else 0)")
      ->check(CLI::Range(0, 232));
  app->add_option("--security", o->security,
                  "DDS Security keystore (`iplan security create-keystore`); default: $IPLAN_SECURITY, else none");
  app->add_option("--enclave", o->enclave,
                  "with --security: the enclave to authenticate as (its permissions apply)")
      ->capture_default_str();
}

std::unique_ptr<dds::Participant> MakeParticipant(const DdsOptions& o, const std::string& name, bool track) {
  dds::ParticipantOptions p;
  p.vendor = o.vendor.empty() ? dds::DefaultVendor() : dds::ParseVendor(o.vendor);
  p.domain_id = o.domain >= 0 ? o.domain : dds::DefaultDomain();
  p.name = name;
  p.track_endpoints = track;
  p.security_dir = o.security.empty() ? dds::DefaultSecurityDir() : o.security;
  if (!p.security_dir.empty()) {
    p.enclave = o.enclave;
    p.name = o.enclave;
  }
  return dds::Participant::Create(p);
}

std::string DdsTopicName(const std::string& name) {
  if (name.rfind("rt/", 0) == 0) return name;
  if (!name.empty() && name[0] == '/') return "rt" + name;
  return "rt/" + name;
}

std::string RosTopicName(const std::string& dds_name) {
  if (dds_name.rfind("rt/", 0) == 0) return dds_name.substr(2);
  return dds_name;
}

std::optional<framework::TopicDescription> FindCatalogueTopic(const std::string& dds_name) {
  for (const auto& t : framework::topics::All()) {
    if (t.name == dds_name) return t;
  }
  return std::nullopt;
}

std::string Tail(const std::string& text, size_t lines) {
  size_t pos = text.size();
  for (size_t n = 0; n <= lines && pos > 0; ++n) {
    pos = text.rfind('\n', pos - 1);
    if (pos == std::string::npos) return text;
  }
  return text.substr(pos + 1);
}

}  // namespace iplan::cli
