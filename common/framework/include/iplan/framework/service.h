// The lifecycle every iplan service follows (after rclcpp's lifecycle nodes):
//
//   unconfigured --configure--> configured --activate--> active
//        ^                          |  ^                    |
//        +--------cleanup-----------+  +----deactivate------+
//
// Each transition returns success or a reason. RunService() is the whole
// main() of a service executable: command line, strict configuration,
// participant, lifecycle, SIGINT/SIGTERM, and systemd readiness/watchdog
// notifications when NOTIFY_SOCKET is set.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "iplan/framework/config.h"
#include "iplan/framework/node.h"

namespace iplan::framework {

/// Success, or failure with a reason.
struct Result {
  bool ok = true;
  std::string reason;
  static Result Ok() { return {}; }
  static Result Fail(std::string why) { return {false, std::move(why)}; }
};

class Service {
 public:
  virtual ~Service() = default;
  /// Reads the service's section of the configuration (keys it does not read
  /// are reported as unknown), creates publishers and subscriptions.
  virtual Result OnConfigure(ConfigSection& config, Node& node) = 0;
  /// Starts work (timers, processing). Messages may arrive from now on.
  virtual Result OnActivate(Node& node) { return Result::Ok(); }
  /// Stops work; the service may be activated again.
  virtual Result OnDeactivate(Node& node) { return Result::Ok(); }
  /// Releases what OnConfigure acquired.
  virtual Result OnCleanup(Node& node) { return Result::Ok(); }
  /// Why this service, as configured, must not run without DDS Security
  /// (e.g. "supervisor.mode is deployment"), or "" when it may. Asked after
  /// OnConfigure: without a keystore and without --insecure the service then
  /// stops with exit code 2 before activating.
  virtual std::string SecurityRequiredBy() const { return ""; }
};

struct ServiceInfo {
  std::string name;         ///< e.g. "perception"; also the config section
  std::string description;  ///< one line for --help
};

/// Exit codes of a service process (systemd: RestartPreventExitStatus=2).
enum ExitCode { kExitOk = 0, kExitRuntimeError = 1, kExitConfigError = 2 };

/// Runs a service to completion; returns the process exit code.
/// Command line: --config FILE, --dds VENDOR, --domain N, --log-level LEVEL,
/// --check-config (load and validate, then exit), --security DIR /
/// --insecure / --require-security (DDS Security: without a keystore the
/// service says so at start, and refuses to start, exit code 2, when
/// --require-security or Service::SecurityRequiredBy asks for one, unless
/// --insecure or IPLAN_INSECURE=1 says running unsecured is meant).
int RunService(int argc, char** argv, const ServiceInfo& info,
               const std::function<std::unique_ptr<Service>()>& make);

/// The shipped configuration file of a service: $IPLAN_CONFIG_DIR/NAME.yaml,
/// else the installed or source config folder. Empty when none exists.
std::string DefaultConfigFile(const std::string& service_name);

/// The shipped configuration folder, the one DefaultConfigFile("supervisor")
/// is in (the cell's tools read several services' files from it). Empty when
/// none exists.
std::string DefaultConfigDir();

}  // namespace iplan::framework
