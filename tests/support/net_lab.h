// Several "computers" on one Linux machine for multi-host tests: one network
// namespace per host, each with an `eth0` (a veth pair) plugged into a
// bridge that lives in a namespace of its own (the switch), so nothing is
// added to the machine's own network. Addresses 10.201.0.<n>/24 in the order
// the hosts are given; multicast is routed out of eth0.
//
// Faults act where a real one would: `SetLink(host, false)` takes the
// host's switch port down (a pulled cable: the host keeps its address, its
// eth0 loses carrier); `SetLoss` drops that share of the packets a host
// receives (nftables `numgen random`); `SetDelay` adds a one-way delay on a
// host's eth0 where the kernel has netem (`DelayAvailable()`).
//
// Names are unique per run (iplan-<pid>-<host>); the destructor kills what
// still runs in the namespaces and deletes them, and the constructor deletes
// namespaces left by runs that died (their pid is gone). Needs root.
#pragma once

#include <sys/types.h>

#include <map>
#include <string>
#include <vector>

namespace iplan::testing {

class NetLab {
 public:
  /// Empty when namespaces can be made here, else why not (not root, no
  /// `ip`, the kernel refuses).
  static std::string Unavailable();

  /// Creates the switch and the hosts; throws std::runtime_error naming the
  /// command that failed (after cleaning up what was made).
  explicit NetLab(const std::vector<std::string>& hosts);
  ~NetLab();
  NetLab(const NetLab&) = delete;
  NetLab& operator=(const NetLab&) = delete;

  /// The namespace of `host` (for `ip netns exec`, setns).
  std::string Namespace(const std::string& host) const;
  /// The host's IPv4 address on the cell network.
  std::string Address(const std::string& host) const;
  /// argv prefix running a command on `host`: {ip, netns, exec, <ns>}.
  std::vector<std::string> On(const std::string& host) const;

  /// Plugs (true) or unplugs (false) the host's cable at the switch.
  void SetLink(const std::string& host, bool up);
  /// Drops `percent` (0-100) of the packets `host` receives; 0 removes the
  /// rule.
  void SetLoss(const std::string& host, int percent);
  /// Empty when nftables works in the hosts, else why not.
  std::string LossUnavailable();
  /// Empty when `tc qdisc ... netem` works here, else the kernel's answer.
  std::string DelayUnavailable();
  /// Adds a fixed one-way delay (ms) on the host's eth0; 0 removes it.
  void SetDelay(const std::string& host, int ms);

  /// Runs `argv` (argv[0] a path); returns the exit code, output in `out`.
  static int Run(const std::vector<std::string>& argv, std::string* out = nullptr);
  /// The path of the `ip` tool ("" when missing).
  static std::string IpTool();

 private:
  void Must(const std::vector<std::string>& argv);
  void Teardown();
  static void RemoveStale();

  std::string prefix_;
  std::vector<std::string> hosts_;
  std::map<std::string, int> index_;
  std::vector<std::string> made_;  // namespaces created, switch first
};

/// Moves the calling thread into a network namespace for its lifetime (the
/// test process's own participant then sits on that host); threads it starts
/// meanwhile inherit the namespace. Throws std::runtime_error on failure.
class InNamespace {
 public:
  explicit InNamespace(const std::string& ns);
  ~InNamespace();
  InNamespace(const InNamespace&) = delete;
  InNamespace& operator=(const InNamespace&) = delete;

 private:
  int home_ = -1;
};

}  // namespace iplan::testing
