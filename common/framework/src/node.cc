#include "iplan/framework/node.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "iplan/core/params.h"

namespace iplan::framework {
namespace {

std::string HostName() {
  char buf[256] = {0};
  if (gethostname(buf, sizeof(buf) - 1) != 0) return "unknown";
  return buf;
}

std::string Fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

std::string Join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& x : v) out += (out.empty() ? "" : ", ") + x;
  return out;
}

}  // namespace

std::string NodeOptions::Validate() const {
  if (!(diagnostics_period >= 0) || !std::isfinite(diagnostics_period)) {
    return "diagnostics_period must be >= 0, got " + core::ParamText(diagnostics_period);
  }
  if (!(max_stamp_ahead >= 0 && max_stamp_ahead <= 60)) {
    return "max_stamp_ahead must be in [0, 60], got " + core::ParamText(max_stamp_ahead);
  }
  if (frame_id.empty()) return "frame_id must not be empty";
  if (realtime_priority < 0 || realtime_priority > 99) {
    return "realtime_priority must be in 0..99, got " + std::to_string(realtime_priority);
  }
  return "";
}

Node::Node(std::string name, dds::Participant& participant, NodeOptions options)
    : name_(std::move(name)), participant_(participant), options_(std::move(options)) {
  log_ = spdlog::get(name_);
  if (!log_) log_ = spdlog::stderr_color_mt(name_);
  if (options_.hardware_id.empty()) options_.hardware_id = HostName();
  if (options_.diagnostics_period > 0) {
    diagnostics_writer_ = &Advertise(topics::Diagnostics());
    AddTimer(std::chrono::nanoseconds(static_cast<int64_t>(options_.diagnostics_period * 1e9)),
             [this] { PublishDiagnostics(); });
  }
}

Node::~Node() {
  // Readers detach from the participant's wait set before it goes away.
  subscriptions_.clear();
  writers_.clear();
}

int Node::AddTimer(std::chrono::nanoseconds period, std::function<void()> cb) {
  const int id = next_timer_id_++;
  timers_[id] = Timer{period, std::chrono::steady_clock::now() + period, std::move(cb)};
  return id;
}

void Node::CancelTimer(int id) { timers_.erase(id); }

void Node::RunTimers() {
  const auto now = std::chrono::steady_clock::now();
  // Copy the ids: a timer callback may add or cancel timers.
  std::vector<int> due;
  for (auto& [id, t] : timers_) {
    if (t.next <= now) due.push_back(id);
  }
  for (int id : due) {
    auto it = timers_.find(id);
    if (it == timers_.end()) continue;
    // Keep the phase; skip missed periods instead of bursting.
    Timer& t = it->second;
    t.next += t.period;
    if (t.next < now) t.next = now + t.period;
    auto cb = t.cb;
    RunGuarded(nullptr, "timer", cb);
  }
}

void Node::SpinOnce(std::chrono::nanoseconds max_wait) {
  // Samples left over from the last spin are due now: no waiting for more.
  auto wait = backlog_.empty() ? max_wait : std::chrono::nanoseconds(0);
  const auto now = std::chrono::steady_clock::now();
  for (const auto& [id, t] : timers_) {
    wait = std::min<std::chrono::nanoseconds>(wait, std::max<std::chrono::nanoseconds>(t.next - now, std::chrono::nanoseconds(0)));
  }
  if (const auto due = CheckDeadlines()) {
    wait = std::min<std::chrono::nanoseconds>(wait, std::max<std::chrono::nanoseconds>(*due - now, std::chrono::nanoseconds(0)));
  }
  if (wait.count() > 0 || !subscriptions_.empty()) {
    participant_.Wait(std::max(wait, std::chrono::nanoseconds(1)), &ready_);
  }
  // The ready readers, then the ones cut short last time (their data
  // status was cleared by the first take: the wait set does not report them
  // again until a new sample comes), each once.
  due_.clear();
  for (dds::AnyReader* r : ready_) {
    auto it = by_reader_.find(r);
    if (it == by_reader_.end()) continue;
    HandleEvents(*it->second);
    due_.push_back(it->second);
  }
  for (SubscriptionBase* sub : backlog_) {
    if (std::find(due_.begin(), due_.end(), sub) == due_.end()) due_.push_back(sub);
  }
  backlog_.clear();
  for (SubscriptionBase* sub : due_) {
    if (sub->Dispatch(*this)) backlog_.push_back(sub);
  }
  CheckDeadlines();
  RunTimers();
}

void Node::SpinUntil(const std::function<bool()>& stop, const std::function<void()>& on_idle) {
  while (!stop()) {
    SpinOnce(std::chrono::milliseconds(50));
    if (on_idle) on_idle();
  }
}

std::optional<std::chrono::steady_clock::time_point> Node::CheckDeadlines() {
  const auto now = std::chrono::steady_clock::now();
  std::optional<std::chrono::steady_clock::time_point> next;
  // By index: an event callback may subscribe to more topics.
  for (std::size_t i = 0; i < subscriptions_.size(); ++i) {
    SubscriptionBase& sub = *subscriptions_[i];
    if (sub.deadline.count() <= 0 || !sub.last_sample) continue;
    auto due = *sub.last_sample + sub.deadline * (sub.missed_periods + 1);
    if (now >= due) {
      // One event per period without a sample, as the DDS policy reports.
      const int periods = static_cast<int>((now - *sub.last_sample) / sub.deadline);
      const int change = std::max(1, periods - sub.missed_periods);
      sub.missed_periods += change;
      sub.deadline_misses_total += change;
      HandleEvent(sub, dds::ReaderEvent{dds::EventKind::kDeadlineMissed, sub.deadline_misses_total, change, 0});
      due = *sub.last_sample + sub.deadline * (sub.missed_periods + 1);
    }
    if (!next || due < *next) next = due;
  }
  return next;
}

void Node::HandleEvents(SubscriptionBase& sub) {
  for (const dds::ReaderEvent& e : sub.reader->TakeEvents()) HandleEvent(sub, e);
}

void Node::HandleEvent(SubscriptionBase& sub, const dds::ReaderEvent& e) {
  const std::string& topic = sub.reader->topic();
  switch (e.kind) {
    case dds::EventKind::kDeadlineMissed:
      sub.stats.deadline_misses += static_cast<uint64_t>(e.count_change);
      if (sub.stats.deadline_misses == static_cast<uint64_t>(e.count_change) || sub.stats.deadline_misses % 100 == 0) {
        log_->warn("{}: deadline missed ({} so far)", topic, sub.stats.deadline_misses);
      }
      break;
    case dds::EventKind::kLivelinessLost:
      sub.stats.liveliness_lost += static_cast<uint64_t>(e.count_change);
      sub.stats.alive_writers = e.current;
      log_->warn("{}: a writer lost liveliness ({} alive)", topic, e.current);
      break;
    case dds::EventKind::kLivelinessRegained:
      sub.stats.alive_writers = e.current;
      log_->info("{}: writer alive ({} alive)", topic, e.current);
      break;
    case dds::EventKind::kIncompatibleQos:
      sub.stats.incompatible_qos += static_cast<uint64_t>(e.count_change);
      log_->error("{}: a writer offers incompatible QoS (policy id {})", topic, e.current);
      break;
    case dds::EventKind::kMatched:
    case dds::EventKind::kUnmatched:
      log_->debug("{}: {} ({} matched)", topic, dds::ToString(e.kind), e.current);
      break;
  }
  if (on_event_) {
    auto cb = on_event_;
    RunGuarded(&sub, "event callback", [&] { cb(topic, e); });
  }
}

void Node::Reject(SubscriptionBase& sub, const std::string& why) {
  ++sub.stats.rejected;
  sub.stats.last_rejection = why;
  if (sub.stats.rejected == 1 || sub.stats.rejected % 100 == 0) {
    log_->warn("{}: rejected message ({} so far): {}", sub.reader->topic(), sub.stats.rejected, why);
  }
}

bool Node::AcceptWriter(SubscriptionBase& sub, const dds::SampleInfo& info) {
  if (sub.entitled.empty()) return true;
  if (std::find(sub.entitled.begin(), sub.entitled.end(), info.writer_name) != sub.entitled.end()) return true;
  const std::string who = info.writer_name.empty() ? "(unnamed)" : info.writer_name;
  ++sub.stats.ignored_writers;
  sub.stats.last_ignored_writer = who;
  if (sub.ignored_names.size() < 64 && sub.ignored_names.insert(who).second) {
    log_->warn("{}: ignoring samples from '{}', not entitled to write it (entitled: {})", sub.reader->topic(), who,
               Join(sub.entitled));
  }
  return false;
}

bool Node::AcceptFrame(SubscriptionBase& sub, const std::string& frame_id) {
  if (!sub.check_frame || frame_id == options_.frame_id) return true;
  Reject(sub, "frame_id '" + frame_id + "' is not the cell frame '" + options_.frame_id + "'");
  return false;
}

bool Node::AcceptStamp(SubscriptionBase& sub, uint64_t writer, int64_t stamp_ns) {
  const int64_t now_ns = msg::ToNanoseconds(msg::Now());
  const int64_t ahead_ns = stamp_ns - now_ns;
  if (ahead_ns > static_cast<int64_t>(options_.max_stamp_ahead * 1e9)) {
    Reject(sub, "stamp " + Fmt(ahead_ns * 1e-9) + " s ahead of this host's clock (tolerance " +
                    Fmt(options_.max_stamp_ahead) + " s)");
    return false;
  }
  auto [it, inserted] = sub.clocks.emplace(writer, SubscriptionBase::WriterClock{stamp_ns, 0});
  if (inserted) return true;
  SubscriptionBase::WriterClock& c = it->second;
  if (stamp_ns < c.last_ns) {
    if (++c.backwards < kResyncAfter) {
      Reject(sub, "stamp went backwards by " + Fmt((c.last_ns - stamp_ns) * 1e-9) + " s");
      return false;
    }
    log_->warn("{}: a writer's stamps went backwards {} times in a row (by {} s): its clock stepped back; "
               "ordering restarts from the new stamp",
               sub.reader->topic(), c.backwards, Fmt((c.last_ns - stamp_ns) * 1e-9));
  }
  c.last_ns = stamp_ns;
  c.backwards = 0;
  return true;
}

std::vector<std::string> Node::EntitledWriters(const std::string& topic, const std::vector<std::string>& catalogue) const {
  // Configuration keys may use the wire name ("rt/iplan/...") or the ROS name
  // ("/iplan/..."), remapped or the catalogue's.
  const auto ros = [](const std::string& t) { return t.rfind("rt/", 0) == 0 ? t.substr(2) : t; };
  const std::string catalogue_name = topics::CatalogueName(topic);
  for (const std::string& key : {topic, ros(topic), catalogue_name, ros(catalogue_name)}) {
    if (auto it = options_.entitled_writers.find(key); it != options_.entitled_writers.end()) return it->second;
  }
  return catalogue;
}

bool Node::CountRejection(const std::string& input, const std::optional<std::string>& rejection) {
  if (!rejection) return false;
  const uint64_t n = ++core_rejections_[input];
  SetDiagnosticValue("rejected_inputs/" + input, std::to_string(n));
  if (n == 1 || n % 100 == 0) log_->warn("{} rejected ({} so far): {}", input, n, *rejection);
  return true;
}

void Node::RecordCycleTime(double seconds) {
  cycle_times_.push_back(seconds);
  if (cycle_times_.size() > 1000) cycle_times_.pop_front();
}

void Node::SetState(const std::string& state, uint8_t level) {
  state_ = state;
  level_ = level;
}

void Node::SetDiagnosticValue(const std::string& key, const std::string& value) { extra_values_[key] = value; }

TopicStats Node::stats(const std::string& topic) const {
  for (const auto& s : subscriptions_) {
    if (s->reader->topic() == topic) return s->stats;
  }
  return {};
}

msg::DiagnosticArray Node::MakeDiagnostics() const {
  msg::DiagnosticArray a;
  a.header.stamp = msg::Now();
  msg::DiagnosticStatus s;
  s.name = name_;
  s.hardware_id = options_.hardware_id;
  s.message = state_;
  s.level = level_;
  auto add = [&s](const std::string& k, const std::string& v) { s.values.push_back({k, v}); };
  add("state", state_);
  uint64_t rejected = 0, misses = 0, lost = 0, errors = 0, ignored = 0;
  for (const auto& sub : subscriptions_) {
    ignored += sub->stats.ignored_writers;
    rejected += sub->stats.rejected;
    misses += sub->stats.deadline_misses;
    lost += sub->stats.liveliness_lost;
    errors += sub->stats.callback_errors;
  }
  if (!cycle_times_.empty()) {
    std::vector<double> v(cycle_times_.begin(), cycle_times_.end());
    std::sort(v.begin(), v.end());
    add("cycle_time_last_s", Fmt(cycle_times_.back()));
    add("cycle_time_p50_s", Fmt(v[v.size() / 2]));
    add("cycle_time_p99_s", Fmt(v[std::min(v.size() - 1, v.size() * 99 / 100)]));
    add("cycle_time_max_s", Fmt(v.back()));
  }
  add("deadline_misses", std::to_string(misses));
  add("liveliness_lost", std::to_string(lost));
  add("rejected_messages", std::to_string(rejected));
  add("callback_errors", std::to_string(errors));
  add("ignored_writers", std::to_string(ignored));
  for (const auto& sub : subscriptions_) {
    const std::string& t = sub->reader->topic();
    add("received/" + t, std::to_string(sub->stats.received));
    add("rejected/" + t, std::to_string(sub->stats.rejected));
    add("deadline_misses/" + t, std::to_string(sub->stats.deadline_misses));
    add("liveliness_lost/" + t, std::to_string(sub->stats.liveliness_lost));
    add("alive_writers/" + t, std::to_string(sub->stats.alive_writers));
    if (!sub->stats.last_rejection.empty()) add("last_rejection/" + t, sub->stats.last_rejection);
    if (sub->stats.ignored_writers > 0) {
      add("ignored_writers/" + t, std::to_string(sub->stats.ignored_writers));
      add("last_ignored_writer/" + t, sub->stats.last_ignored_writer);
    }
  }
  for (const auto& [k, v] : extra_values_) add(k, v);
  if (s.level == msg::DiagnosticStatus::OK && (rejected > 0 || misses > 0 || lost > 0 || errors > 0 || ignored > 0)) {
    s.level = msg::DiagnosticStatus::WARN;
  }
  a.status.push_back(std::move(s));
  return a;
}

void Node::PublishDiagnostics() {
  if (!diagnostics_writer_) return;
  std::string err;
  if (!diagnostics_writer_->Write(MakeDiagnostics(), &err)) log_->warn("diagnostics not published: {}", err);
}

}  // namespace iplan::framework
