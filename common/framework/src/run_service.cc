#include <csignal>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "iplan/core/params.h"
#include "iplan/dds/security.h"
#include "iplan/framework/enclaves.h"
#include "iplan/framework/service.h"
#include "iplan/framework/service_file.h"
#include "iplan/framework/topics.h"
#include "realtime.h"
#include "iplan/framework/systemd.h"

namespace iplan::framework {
namespace {

volatile std::sig_atomic_t g_stop = 0;

void OnSignal(int) { g_stop = 1; }

bool FileExists(const std::string& p) { return std::ifstream(p).good(); }

// The service's file with the --set overrides applied, and the framework's
// `node` section read from it. False (the problems printed) on a bad one.
// The topic remappings: `node.remap` ({FROM: TO}), then the command line's
// --remap FROM:=TO rules over it; applied to the catalogue. False (printed)
// on a bad rule.
bool ApplyRemappings(const std::string& name, const std::map<std::string, std::string>& remap,
                     const std::vector<std::string>& rules) {
  std::map<std::string, std::string> from_to = remap;
  for (const std::string& rule : rules) {
    std::string from, to, error;
    if (!topics::ParseRemapRule(rule, &from, &to, &error)) {
      std::cerr << "iplan-" << name << ": --remap: " << error << "\n";
      return false;
    }
    from_to[from] = to;
  }
  // Config keys may be written without the leading slash; normalise.
  std::map<std::string, std::string> normalised;
  for (const auto& [from, to] : from_to) {
    normalised[from.empty() || from[0] == '/' ? from : "/" + from] = to;
  }
  if (const std::string why = topics::SetRemappings(normalised); !why.empty()) {
    std::cerr << "iplan-" << name << ": " << why << "\n";
    return false;
  }
  return true;
}

bool LoadConfiguration(const std::string& name, const std::string& config_file,
                       const std::vector<std::string>& overrides, const std::vector<std::string>& remaps,
                       std::unique_ptr<ServiceFile>* config, NodeOptions* nopts) {
  try {
    core::Overrides parsed;
    for (const std::string& o : overrides) parsed.push_back(core::ParseOverride(o));
    *config = std::make_unique<ServiceFile>(config_file, parsed);
    const NodeSettings& node = (*config)->node();
    if (node.Validate().empty()) *nopts = node.options;  // else refused after OnConfigure, naming the key
    if (!ApplyRemappings(name, node.remap, remaps)) return false;
  } catch (const ConfigError& e) {
    std::cerr << "iplan-" << name << ": configuration error:\n" << e.what() << "\n";
    return false;
  }
  return true;
}

// OnConfigure, then every key of the file accounted for: false (the
// problems printed) when the configuration is bad.
bool Configure(const std::string& name, ServiceFile* config, Service* service, Node* node) {
  ConfigSection section = config->Section(name);
  const Result r = service->OnConfigure(section, *node);
  try {
    config->Finish();
  } catch (const ConfigError& e) {
    std::cerr << "iplan-" << name << ": configuration error:\n" << e.what() << "\n";
    // A parameter file the service loaded failed too: say so as well.
    if (!r.ok && std::string(e.what()).find(r.reason) == std::string::npos) std::cerr << "iplan-" << name << ": configure failed: " << r.reason << "\n";
    return false;
  }
  if (!r.ok) {
    std::cerr << "iplan-" << name << ": configure failed: " << r.reason << "\n";
    return false;
  }
  return true;
}

// --dds, --domain and --security, or their environment defaults. False
// (printed) on a bad one, including a missing or invalid enclave: a
// restart cannot fix those (exit code 2).
bool ParticipantOptionsFrom(const std::string& name, const std::string& vendor_text, int domain,
                            const std::string& security_dir, dds::ParticipantOptions* popts) {
  popts->name = EnclaveName(name);
  try {
    popts->vendor = vendor_text.empty() ? dds::DefaultVendor() : dds::ParseVendor(vendor_text);
    popts->domain_id = domain >= 0 ? domain : dds::DefaultDomain();
    popts->security_dir = security_dir.empty() ? dds::DefaultSecurityDir() : security_dir;
    if (!popts->security_dir.empty()) dds::LoadEnclave(popts->security_dir, popts->name);
  } catch (const std::exception& e) {
    std::cerr << "iplan-" << name << ": " << e.what() << "\n";
    return false;
  }
  return true;
}

void AddSecurityOption(CLI::App* app, const std::string& name, std::string* dir) {
  app->add_option("--security", *dir,
                  "DDS Security keystore (`iplan security create-keystore`): the service authenticates as "
                  "enclave " + EnclaveName(name) + ", encrypts and may use only its topics (default: "
                  "$IPLAN_SECURITY, else no security)");
}

// The service's command line.
struct CommandLine {
  std::string config_file;
  std::string vendor_text;
  int domain = -1;
  std::string security_dir;
  bool insecure = false;          ///< run without DDS Security on purpose
  bool require_security = false;  ///< refuse to start without it, unless insecure
  std::string log_level = "info";
  bool check_only = false;
  std::vector<std::string> overrides;
  std::vector<std::string> remaps;
};

// Without a keystore, say what that means, once, at start. True when the
// service may run so; false (said why) when it must not: --require-security
// (the systemd units) or the configured service's own need (`required_by`,
// e.g. a supervisor in deployment mode), unless --insecure said it is meant.
bool AcceptSecurityMode(const std::string& name, const dds::ParticipantOptions& popts, bool insecure,
                        const std::string& required_by) {
  if (!popts.security_dir.empty()) return true;
  // The service's own logger (the Node takes it over), on stderr.
  auto log = spdlog::get(name);
  if (!log) log = spdlog::stderr_color_mt(name);
  const std::string exposure =
      "any process on the network can read this service's topics and write to it under any participant name "
      "(docs/safety.md, \"Threat model\")";
  if (insecure) {
    log->warn("DDS Security is off on purpose (--insecure): {}", exposure);
    return true;
  }
  if (!required_by.empty()) {
    log->error("refusing to start without DDS Security ({}): give the cell's keystore (--security DIR or "
               "IPLAN_SECURITY=DIR, docs/deployment.md), or --insecure (IPLAN_INSECURE=1) to run unsecured on "
               "purpose",
               required_by);
    return false;
  }
  log->warn("no DDS Security (no --security, no IPLAN_SECURITY): {}; pass --insecure to run so on purpose",
            exposure);
  return true;
}

// IPLAN_INSECURE from the environment: true for 1/true/yes, false when unset,
// empty or 0/false/no; anything else is an error (thrown).
bool InsecureFromEnvironment() {
  const char* v = std::getenv("IPLAN_INSECURE");
  const std::string s = v ? v : "";
  if (s.empty() || s == "0" || s == "false" || s == "no") return false;
  if (s == "1" || s == "true" || s == "yes") return true;
  throw std::invalid_argument("IPLAN_INSECURE='" + s + "' is not 1/true/yes or 0/false/no");
}

// --insecure / IPLAN_INSECURE against the keystore and --require-security,
// before the participant exists. False (said why) when the service must not
// start.
bool DecideSecurity(const std::string& name, const dds::ParticipantOptions& popts, CommandLine* cl) {
  try {
    cl->insecure = cl->insecure || InsecureFromEnvironment();
  } catch (const std::exception& e) {
    std::cerr << "iplan-" << name << ": " << e.what() << "\n";
    return false;
  }
  if (cl->insecure && !popts.security_dir.empty()) {
    std::cerr << "iplan-" << name << ": --insecure (or IPLAN_INSECURE) contradicts the DDS Security keystore "
              << popts.security_dir << " (--security or IPLAN_SECURITY): give one of them\n";
    return false;
  }
  return AcceptSecurityMode(name, popts, cl->insecure,
                            cl->require_security ? "--require-security, as the systemd units pass it" : "");
}

void LogConfiguring(Node& node, const std::string& config_file, const dds::ParticipantOptions& popts) {
  node.log().info("configuring from {} on {} domain {}{}", config_file.empty() ? "(defaults)" : config_file,
                  dds::ToString(popts.vendor), popts.domain_id,
                  popts.security_dir.empty() ? "" : ", DDS Security enclave " + popts.name + " of " + popts.security_dir);
}

// Activate, spin until SIGINT/SIGTERM, deactivate, clean up. False when
// activation failed (cleaned up, logged).
bool RunActive(Service* service, Node* node) {
  Result r = service->OnActivate(*node);
  if (!r.ok) {
    node->log().error("activate failed: {}", r.reason);
    service->OnCleanup(*node);
    return false;
  }
  node->SetState("active");
  node->PublishDiagnostics();
  systemd::NotifyReady("active");
  node->log().info("active");
  systemd::Watchdog watchdog;
  node->SpinUntil([] { return g_stop != 0; }, [&watchdog] { watchdog.Tick(); });
  systemd::NotifyStopping();
  node->log().info("stopping");
  r = service->OnDeactivate(*node);
  if (!r.ok) node->log().warn("deactivate: {}", r.reason);
  node->SetState("inactive");
  node->PublishDiagnostics();
  r = service->OnCleanup(*node);
  if (!r.ok) node->log().warn("cleanup: {}", r.reason);
  return true;
}

void AddOptions(const ServiceInfo& info, CLI::App* app, CommandLine* cl) {
  app->add_option("-c,--config", cl->config_file, "YAML configuration file")
      ->capture_default_str();
  app->add_option("--dds", cl->vendor_text,
                  "DDS vendor: cyclonedds or fastdds (default: $IPLAN_DDS, else cyclonedds)");
  app->add_option("--domain", cl->domain, "DDS domain id 0-232 (default: $IPLAN_DOMAIN, else 0)");
  AddSecurityOption(app, info.name, &cl->security_dir);
  app->add_flag("--insecure", cl->insecure,
                "run without DDS Security on purpose (also IPLAN_INSECURE=1): anyone on the network can then "
                "read the cell and claim any participant's name (docs/safety.md); contradicts --security");
  app->add_flag("--require-security", cl->require_security,
                "refuse to start (exit code 2) without a DDS Security keystore unless --insecure (the systemd "
                "units pass it)");
  app->add_option("--log-level", cl->log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}))
      ->capture_default_str();
  app->add_option("--set", cl->overrides,
                  "override a setting of the configuration file: KEY=VALUE with a dotted key from the "
                  "file's top level and a YAML value, e.g. --set " + info.name + ".seed=3 (repeatable); "
                  "a key may continue into a parameter file the configuration names, e.g. "
                  "--set trajopt.planner.max_iterations=30 (docs/configuration.md)");
  app->add_option("-r,--remap", cl->remaps,
                  "rename a topic, ROS 2's FROM:=TO, e.g. --remap /iplan/robot/trajectory:=/arm_controller/"
                  "joint_trajectory (repeatable; over node.remap of the configuration; docs/topics.md)");
  app->add_flag("--check-config", cl->check_only,
                "read the configuration and every parameter file it names as the service would (all "
                "keys, types and ranges, Validate() included), print the problems and exit: 0 valid, "
                "2 not");
}

}  // namespace

std::string DefaultConfigFile(const std::string& service_name) {
  std::vector<std::string> dirs;
  if (const char* d = std::getenv("IPLAN_CONFIG_DIR"); d && *d) dirs.emplace_back(d);
  dirs.emplace_back(IPLAN_INSTALL_CONFIG_DIR);
  dirs.emplace_back(IPLAN_SOURCE_CONFIG_DIR);
  for (const auto& d : dirs) {
    const std::string f = d + "/" + service_name + ".yaml";
    if (FileExists(f)) return f;
  }
  return "";
}

std::string DefaultConfigDir() {
  const std::string f = DefaultConfigFile("supervisor");
  return f.empty() ? f : f.substr(0, f.rfind('/'));
}

int RunService(int argc, char** argv, const ServiceInfo& info,
               const std::function<std::unique_ptr<Service>()>& make) {
  CLI::App app{"iplan-" + info.name + ": " + info.description +
               "\n\nA service of the iplan cell. It reads its settings from a YAML file "
               "(section '" + info.name + "', framework settings in section 'node'), talks "
               "DDS on the chosen vendor and domain, publishes diagnostics on /diagnostics, "
               "and stops cleanly on SIGINT or SIGTERM. Exit codes: 0 stopped, 1 runtime "
               "error, 2 bad configuration."};
  CommandLine cl;
  cl.config_file = DefaultConfigFile(info.name);
  AddOptions(info, &app, &cl);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? kExitOk : kExitConfigError;
  }
  spdlog::set_level(spdlog::level::from_str(cl.log_level));
  spdlog::set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");

  dds::ParticipantOptions popts;
  if (!ParticipantOptionsFrom(info.name, cl.vendor_text, cl.domain, cl.security_dir, &popts)) return kExitConfigError;
  if (!DecideSecurity(info.name, popts, &cl)) return kExitConfigError;

  std::unique_ptr<ServiceFile> config;
  NodeOptions nopts;
  if (!LoadConfiguration(info.name, cl.config_file, cl.overrides, cl.remaps, &config, &nopts)) return kExitConfigError;

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  // Before the participant: its threads inherit the scheduling policy.
  for (const std::string& why : internal::ApplyRealtime(nopts.realtime_priority, nopts.lock_memory)) {
    spdlog::warn("iplan-{}: {}", info.name, why);
  }

  std::unique_ptr<dds::Participant> participant;
  std::unique_ptr<Node> node;
  std::unique_ptr<Service> service;
  try {
    participant = dds::Participant::Create(popts);
    node = std::make_unique<Node>(info.name, *participant, nopts);
    service = make();
    LogConfiguring(*node, cl.config_file, popts);
    if (!Configure(info.name, config.get(), service.get(), node.get())) return kExitConfigError;
    if (const std::string why = service->SecurityRequiredBy(); !why.empty() && popts.security_dir.empty() &&
        !cl.insecure) {
      AcceptSecurityMode(info.name, popts, false, why);
      return kExitConfigError;
    }
    node->SetState("configured");
    if (cl.check_only) {
      std::cout << cl.config_file << ": configuration is valid\n";
      return kExitOk;
    }
    if (!RunActive(service.get(), node.get())) return kExitRuntimeError;
    service.reset();
    node.reset();
    participant.reset();
    return kExitOk;
  } catch (const std::exception& e) {
    std::cerr << "iplan-" << info.name << ": error: " << e.what() << "\n";
    return kExitRuntimeError;
  }
}

}  // namespace iplan::framework
