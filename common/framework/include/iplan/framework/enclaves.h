// The DDS Security enclave of every iplan participant: exactly the topics of
// the catalogue (topics.h) that each service publishes and subscribes, so a
// service's permissions document grants what its node creates and nothing
// more. `iplan security create-keystore` writes one enclave per entry.
#pragma once

#include <string>
#include <vector>

#include "iplan/dds/security.h"

namespace iplan::framework {

/// The enclave name of a service: its participant name, "iplan-" + the
/// service name ("iplan-trajopt").
std::string EnclaveName(const std::string& service_name);

/// One grant per service (perception, intent, collision_risk, trajopt,
/// robot_sim, supervisor) plus "iplan-observer", which may subscribe to every
/// catalogue topic and publish none (`iplan topic echo/list/hz`, `iplan view`,
/// `iplan record`). DDS topic names ("rt/..."). Allocates.
std::vector<dds::EnclaveGrant> CellEnclaves();

/// The observer's enclave name.
inline constexpr const char* kObserverEnclave = "iplan-observer";

}  // namespace iplan::framework
