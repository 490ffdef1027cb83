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

/// What EnsureCellKeystore did.
struct KeystoreReport {
  bool created = false;               ///< the keystore was made now
  std::vector<std::string> reissued;  ///< "<enclave>: <why>", each re-signed by the keystore's CA
};

/// Makes `dir` a keystore this version of the cell runs with: creates it
/// (dds::CreateKeystore: built beside it and renamed into place, so a killed
/// creation never leaves a half keystore at `dir`) when it is missing or an
/// empty folder; otherwise checks every enclave of CellEnclaves() as a
/// service would (dds::LoadEnclave) and that it grants exactly the topics the
/// cell needs now (dds::ReadGrant), and re-issues each one that does not
/// (dds::CreateEnclave, signed by the keystore's own CA). Another process
/// creating the same keystore at the same moment is no error: the one that
/// won is checked and used. Throws std::runtime_error naming the keystore
/// and the reason (e.g. an enclave to re-issue and no CA key in `private/`).
/// Allocates.
KeystoreReport EnsureCellKeystore(const std::string& dir);

/// The keystore of this user's own cell (`iplan demo`, scripts/setup.sh):
/// $XDG_DATA_HOME/iplan/keystore, else $HOME/.local/share/iplan/keystore.
/// Throws std::runtime_error when neither variable is set.
std::string UserKeystoreDir();

}  // namespace iplan::framework
