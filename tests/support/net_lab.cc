#include "net_lab.h"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "iplan/core/process.h"

namespace iplan::testing {
namespace {

constexpr char kPrefix[] = "iplannet-";
constexpr char kSwitch[] = "sw";
constexpr char kLossTable[] = "iplan_loss";

std::string Join(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

// Kills every process still in namespace `ns` and deletes it.
void DeleteNamespace(const std::string& ip, const std::string& ns) {
  std::string pids;
  NetLab::Run({ip, "netns", "pids", ns}, &pids);
  std::istringstream in(pids);
  for (long pid = 0; in >> pid;) {
    if (pid > 1) ::kill(static_cast<pid_t>(pid), SIGKILL);
  }
  NetLab::Run({ip, "netns", "del", ns});
}

}  // namespace

std::string NetLab::IpTool() {
  for (const char* p : {"/usr/sbin/ip", "/sbin/ip", "/usr/bin/ip", "/bin/ip"}) {
    if (::access(p, X_OK) == 0) return p;
  }
  return "";
}

int NetLab::Run(const std::vector<std::string>& argv, std::string* out) {
  core::Process p(argv);
  const auto rc = p.Wait(std::chrono::seconds(20));
  if (out) *out = p.Stdout() + p.Stderr();
  return rc ? *rc : -1;
}

std::string NetLab::Unavailable() {
  if (::geteuid() != 0) return "needs root (network namespaces, veth pairs, a bridge); CI runs as root";
  const std::string ip = IpTool();
  if (ip.empty()) return "the `ip` tool (Debian package iproute2) is not installed";
  const std::string probe = std::string(kPrefix) + std::to_string(getpid()) + "-probe";
  std::string out;
  if (Run({ip, "netns", "add", probe}, &out) != 0) return "`ip netns add` failed: " + out;
  std::string why;
  if (Run({ip, "-n", probe, "link", "add", "probe0", "type", "veth", "peer", "name", "probe1"}, &out) != 0) {
    why = "cannot create a veth pair in a namespace: " + out;
  } else if (Run({ip, "netns", "exec", probe, "/bin/true"}, &out) != 0) {
    why = "`ip netns exec` fails here (it mounts /sys for the namespace): " + out;
  }
  Run({ip, "netns", "del", probe});
  return why;
}

void NetLab::RemoveStale() {
  const std::string ip = IpTool();
  std::string list;
  Run({ip, "netns", "list"}, &list);
  std::istringstream in(list);
  for (std::string line; std::getline(in, line);) {
    const std::string ns = line.substr(0, line.find(' '));
    if (ns.rfind(kPrefix, 0) != 0) continue;
    const std::string rest = ns.substr(sizeof(kPrefix) - 1);
    const long pid = std::strtol(rest.c_str(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) DeleteNamespace(ip, ns);
  }
}

NetLab::NetLab(const std::vector<std::string>& hosts)
    : prefix_(std::string(kPrefix) + std::to_string(getpid()) + "-"), hosts_(hosts) {
  RemoveStale();
  const std::string ip = IpTool();
  const std::string sw = prefix_ + kSwitch;
  try {
    Must({ip, "netns", "add", sw});
    made_.push_back(sw);
    Must({ip, "-n", sw, "link", "add", "br0", "type", "bridge"});
    Must({ip, "-n", sw, "link", "set", "br0", "up"});
    for (std::size_t i = 0; i < hosts.size(); ++i) {
      const std::string& h = hosts[i];
      const std::string ns = prefix_ + h;
      index_[h] = static_cast<int>(i) + 1;
      Must({ip, "netns", "add", ns});
      made_.push_back(ns);
      Must({ip, "-n", ns, "link", "set", "lo", "up"});
      // Created directly in the two namespaces: no name ever exists in the
      // machine's own namespace, so parallel runs cannot collide.
      Must({ip, "link", "add", "eth0", "netns", ns, "type", "veth", "peer", "name", "p" + std::to_string(i + 1),
            "netns", sw});
      Must({ip, "-n", sw, "link", "set", "p" + std::to_string(i + 1), "master", "br0", "up"});
      Must({ip, "-n", ns, "addr", "add", Address(h) + "/24", "dev", "eth0"});
      Must({ip, "-n", ns, "link", "set", "eth0", "up"});
      Must({ip, "-n", ns, "route", "add", "224.0.0.0/4", "dev", "eth0"});
    }
  } catch (...) {
    Teardown();
    throw;
  }
}

NetLab::~NetLab() { Teardown(); }

void NetLab::Teardown() {
  const std::string ip = IpTool();
  // Hosts first (their processes), the switch last.
  for (auto it = made_.rbegin(); it != made_.rend(); ++it) DeleteNamespace(ip, *it);
  made_.clear();
}

void NetLab::Must(const std::vector<std::string>& argv) {
  std::string out;
  if (Run(argv, &out) != 0) throw std::runtime_error("`" + Join(argv) + "` failed: " + out);
}

std::string NetLab::Namespace(const std::string& host) const {
  if (!index_.count(host)) throw std::invalid_argument("no host '" + host + "' in this lab");
  return prefix_ + host;
}

std::string NetLab::Address(const std::string& host) const { return "10.201.0." + std::to_string(index_.at(host)); }

std::vector<std::string> NetLab::On(const std::string& host) const {
  return {IpTool(), "netns", "exec", Namespace(host)};
}

void NetLab::SetLink(const std::string& host, bool up) {
  Must({IpTool(), "-n", prefix_ + kSwitch, "link", "set", "p" + std::to_string(index_.at(host)), up ? "up" : "down"});
}

void NetLab::SetLoss(const std::string& host, int percent) {
  std::vector<std::string> nft = On(host);
  nft.push_back("nft");
  auto with = [&](const std::string& cmd) {
    std::vector<std::string> a = nft;
    a.push_back(cmd);
    return a;
  };
  const std::string table = std::string("inet ") + kLossTable;
  Run(with("delete table " + table));  // absent the first time
  if (percent <= 0) return;
  Must(with("add table " + table));
  Must(with("add chain " + table + " input { type filter hook input priority 0 ; policy accept ; }"));
  // Only what arrives over the cell network: a host's own processes talk
  // over its loopback, which no cable fault touches.
  Must(with("add rule " + table + " input iifname \"eth0\" numgen random mod 100 < " + std::to_string(percent) +
            " drop"));
}

std::string NetLab::LossUnavailable() {
  if (hosts_.empty()) return "no hosts";
  std::vector<std::string> nft = On(hosts_.front());
  nft.insert(nft.end(), {"nft", "list", "tables"});
  std::string out;
  if (Run(nft, &out) != 0) return "nft fails in a host (Debian package nftables): " + out.substr(0, out.find('\n'));
  return "";
}

std::string NetLab::DelayUnavailable() {
  if (hosts_.empty()) return "no hosts";
  std::vector<std::string> tc = On(hosts_.front());
  tc.insert(tc.end(), {"tc", "qdisc", "add", "dev", "eth0", "root", "netem", "delay", "1ms"});
  std::string out;
  if (Run(tc, &out) != 0) return out.empty() ? "tc failed" : out.substr(0, out.find('\n'));
  SetDelay(hosts_.front(), 0);
  return "";
}

void NetLab::SetDelay(const std::string& host, int ms) {
  std::vector<std::string> tc = On(host);
  tc.insert(tc.end(), {"tc", "qdisc", "del", "dev", "eth0", "root"});
  Run(tc);  // absent the first time
  if (ms <= 0) return;
  tc = On(host);
  tc.insert(tc.end(), {"tc", "qdisc", "add", "dev", "eth0", "root", "netem", "delay", std::to_string(ms) + "ms"});
  Must(tc);
}

InNamespace::InNamespace(const std::string& ns) {
  home_ = ::open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
  const int target = ::open(("/run/netns/" + ns).c_str(), O_RDONLY | O_CLOEXEC);
  if (home_ < 0 || target < 0 || ::setns(target, CLONE_NEWNET) != 0) {
    const std::string why = std::strerror(errno);
    if (target >= 0) ::close(target);
    if (home_ >= 0) ::close(home_);
    throw std::runtime_error("cannot enter network namespace " + ns + ": " + why);
  }
  ::close(target);
}

InNamespace::~InNamespace() {
  if (home_ >= 0) {
    ::setns(home_, CLONE_NEWNET);
    ::close(home_);
  }
}

}  // namespace iplan::testing
