// Fast DDS 2.9 backend: the plain message types serialised directly with Fast
// CDR (fastdds_plain_type.h), one wait set per participant.
#include <map>
#include <mutex>
#include <stdexcept>
#include <unordered_map>

#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/core/condition/StatusCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "backend.h"
#include "fastdds_plain_type.h"

namespace iplan::dds::internal {
namespace {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::Duration_t;
using RC = eprosima::fastrtps::types::ReturnCode_t;

constexpr const char* kParticipantProfile = "iplan_participant";

Duration_t ToDuration(std::chrono::nanoseconds ns) {
  if (ns.count() <= 0) return eprosima::fastrtps::c_TimeInfinite;
  return Duration_t(static_cast<int32_t>(ns.count() / 1000000000),
                    static_cast<uint32_t>(ns.count() % 1000000000));
}

const fastdds_plain::PlainTypeEntry& FindOps(const std::string& dds_type) {
  const fastdds_plain::PlainTypeEntry* e = fastdds_plain::FindPlainType(dds_type);
  if (!e) throw std::runtime_error("Fast DDS: no type support for '" + dds_type + "'");
  return *e;
}

void ApplyCommon(const QosProfile& q, fdds::DurabilityQosPolicy* durability,
                 fdds::HistoryQosPolicy* history, fdds::DeadlineQosPolicy* deadline,
                 fdds::LivelinessQosPolicy* liveliness) {
  durability->kind = q.durability == QosProfile::Durability::kTransientLocal
                         ? fdds::TRANSIENT_LOCAL_DURABILITY_QOS
                         : fdds::VOLATILE_DURABILITY_QOS;
  history->kind = fdds::KEEP_LAST_HISTORY_QOS;
  history->depth = q.depth;
  deadline->period = ToDuration(q.deadline);
  liveliness->kind = fdds::AUTOMATIC_LIVELINESS_QOS;
  liveliness->lease_duration = ToDuration(q.liveliness_lease);
  if (q.liveliness_lease.count() > 0) {
    // Assert well within the lease so a live writer is never reported lost.
    liveliness->announcement_period = ToDuration(q.liveliness_lease / 3);
  }
}

std::string GuidText(const eprosima::fastrtps::rtps::GUID_t& g) {
  unsigned char b[16];
  std::copy(g.guidPrefix.value, g.guidPrefix.value + 12, b);
  std::copy(g.entityId.value, g.entityId.value + 4, b + 12);
  return HexGuid(b, 16);
}

class FastParticipant;

// Participant names that remote writers announced in their USER_DATA, by
// writer GUID (kept by the participant's discovery listener).
class WriterNames {
 public:
  void Set(const eprosima::fastrtps::rtps::GUID_t& g, std::string name) {
    std::lock_guard<std::mutex> lock(mu_);
    if (name.empty()) {
      names_.erase(Key(g));
    } else {
      names_[Key(g)] = std::move(name);
    }
  }
  void Erase(const eprosima::fastrtps::rtps::GUID_t& g) {
    std::lock_guard<std::mutex> lock(mu_);
    names_.erase(Key(g));
  }
  std::string Get(const unsigned char* handle16) const {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = names_.find(std::string(reinterpret_cast<const char*>(handle16), 16));
    return it == names_.end() ? std::string() : it->second;
  }

 private:
  static std::string Key(const eprosima::fastrtps::rtps::GUID_t& g) {
    std::string k(16, '\0');
    std::copy(g.guidPrefix.value, g.guidPrefix.value + 12, k.begin());
    std::copy(g.entityId.value, g.entityId.value + 4, k.begin() + 12);
    return k;
  }
  mutable std::mutex mu_;
  std::unordered_map<std::string, std::string> names_;
};

class FastWriter final : public BackendWriter {
 public:
  FastWriter(fdds::Publisher* pub, fdds::DataWriter* w) : publisher_(pub), writer_(w) {}
  ~FastWriter() override { publisher_->delete_datawriter(writer_); }
  bool Write(const void* plain, std::string* error) override {
    // The type support serialises `plain` inside write() (thread-safe) and
    // only reads it.
    if (!writer_->write(const_cast<void*>(plain))) {
      if (error) *error = "Fast DDS DataWriter::write failed";
      return false;
    }
    return true;
  }
  int MatchedReaders() const override {
    fdds::PublicationMatchedStatus s;
    writer_->get_publication_matched_status(s);
    return s.current_count;
  }
  bool WaitForAcknowledgments(std::chrono::nanoseconds timeout) override {
    return writer_->wait_for_acknowledgments(ToDuration(timeout)) == RC::RETCODE_OK;
  }

 private:
  fdds::Publisher* publisher_;
  fdds::DataWriter* writer_;
};

// Liveliness of `r` as events (lost: a writer stopped asserting or left).
void LivelinessEvents(fdds::DataReader* r, std::vector<ReaderEvent>* events) {
  fdds::LivelinessChangedStatus s;
  r->get_liveliness_changed_status(s);
  if (s.not_alive_count_change > 0 || s.alive_count_change < 0) {
    events->push_back({EventKind::kLivelinessLost, s.not_alive_count,
                       std::max(s.not_alive_count_change, -s.alive_count_change), s.alive_count});
  }
  if (s.alive_count_change > 0) {
    events->push_back({EventKind::kLivelinessRegained, s.alive_count, s.alive_count_change, s.alive_count});
  }
}

class FastReader final : public BackendReader {
 public:
  /// `watch`: the data-less reader that tracks liveliness for `r` (may be null).
  FastReader(FastParticipant* owner, fdds::Subscriber* sub, fdds::DataReader* r, fdds::DataReader* watch,
             const WriterNames& names)
      : owner_(owner), subscriber_(sub), reader_(r), watch_(watch), names_(names) {}
  ~FastReader() override;
  bool Take(void* plain, SampleInfo* info) override {
    fdds::SampleInfo si;
    // Deserialised straight into `plain`; a sample that does not deserialise
    // is dropped here (and counted and logged by the type support).
    for (;;) {
      fastdds_plain::ClearDeserializeFailure();
      if (reader_->take_next_sample(plain, &si) != RC::RETCODE_OK) break;
      if (!si.valid_data || fastdds_plain::DeserializeFailed()) continue;  // or dispose/unregister
      info->source_timestamp_ns = si.source_timestamp.to_ns();
      info->reception_ns = NowNs();
      info->writer_id = HashBytes(si.publication_handle.value, 16);
      // Cache per writer; a miss is not cached (discovery may still be on its way).
      auto it = cache_.find(info->writer_id);
      if (it == cache_.end()) {
        std::string name = names_.Get(si.publication_handle.value);
        if (!name.empty()) {
          if (cache_.size() > 4096) cache_.clear();
          it = cache_.emplace(info->writer_id, std::move(name)).first;
        }
      }
      info->writer_name = it == cache_.end() ? std::string() : it->second;
      return true;
    }
    return false;
  }
  void TakeEvents(std::vector<ReaderEvent>* events) override {
    const fdds::StatusMask changes = reader_->get_status_changes();
    if (changes.is_active(fdds::StatusMask::requested_deadline_missed())) {
      fdds::RequestedDeadlineMissedStatus s;
      reader_->get_requested_deadline_missed_status(s);
      if (s.total_count_change > 0) {
        events->push_back({EventKind::kDeadlineMissed, static_cast<int32_t>(s.total_count),
                           static_cast<int32_t>(s.total_count_change), 0});
      }
    }
    // With a watch reader, liveliness is its (the data reader requests an
    // infinite lease and tracks none).
    fdds::DataReader* live = watch_ ? watch_ : reader_;
    if (live->get_status_changes().is_active(fdds::StatusMask::liveliness_changed())) {
      LivelinessEvents(live, events);
    }
    if (changes.is_active(fdds::StatusMask::subscription_matched())) {
      fdds::SubscriptionMatchedStatus s;
      reader_->get_subscription_matched_status(s);
      if (s.current_count_change > 0) {
        events->push_back({EventKind::kMatched, s.total_count, s.current_count_change, s.current_count});
      } else if (s.current_count_change < 0) {
        events->push_back({EventKind::kUnmatched, s.total_count, -s.current_count_change, s.current_count});
      }
    }
    if (changes.is_active(fdds::StatusMask::requested_incompatible_qos())) {
      fdds::RequestedIncompatibleQosStatus s;
      reader_->get_requested_incompatible_qos_status(s);
      if (s.total_count_change > 0) {
        events->push_back({EventKind::kIncompatibleQos, static_cast<int32_t>(s.total_count),
                           static_cast<int32_t>(s.total_count_change),
                           static_cast<int32_t>(s.last_policy_id)});
      }
    }
  }
  int MatchedWriters() const override {
    fdds::SubscriptionMatchedStatus s;
    reader_->get_subscription_matched_status(s);
    return s.current_count;
  }
  fdds::DataReader* reader() const { return reader_; }

 private:
  FastParticipant* owner_;
  fdds::Subscriber* subscriber_;
  fdds::DataReader* reader_;
  fdds::DataReader* watch_;
  const WriterNames& names_;
  std::unordered_map<uint64_t, std::string> cache_;
};

// Keeps the names remote writers announce (always) and the table of
// discovered endpoints for `iplan topic list` (when tracking).
class DiscoveryListener : public fdds::DomainParticipantListener {
 public:
  explicit DiscoveryListener(bool track) : track_(track) {}
  void on_publisher_discovery(fdds::DomainParticipant*,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    using S = eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERY_STATUS;
    if (info.status == S::REMOVED_WRITER) {
      names_.Erase(info.info.guid());
    } else {
      const auto& ud = info.info.m_qos.m_userData.data_vec();
      names_.Set(info.info.guid(), NameFromUserData(ud.data(), ud.size()));
    }
    if (!track_) return;
    Update(GuidText(info.info.guid()), info.info.topicName().to_string(),
           info.info.typeName().to_string(), true,
           info.status == S::REMOVED_WRITER);
  }
  void on_subscriber_discovery(fdds::DomainParticipant*,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
    if (!track_) return;
    using S = eprosima::fastrtps::rtps::ReaderDiscoveryInfo::DISCOVERY_STATUS;
    Update(GuidText(info.info.guid()), info.info.topicName().to_string(),
           info.info.typeName().to_string(), false,
           info.status == S::REMOVED_READER);
  }
  std::vector<EndpointInfo> Endpoints() const {
    std::lock_guard<std::mutex> lock(mu_);
    std::vector<EndpointInfo> out;
    for (const auto& [guid, e] : endpoints_) out.push_back(e);
    return out;
  }
  const WriterNames& names() const { return names_; }

 private:
  void Update(const std::string& guid, const std::string& topic, const std::string& type,
              bool writer, bool removed) {
    std::lock_guard<std::mutex> lock(mu_);
    if (removed) {
      endpoints_.erase(guid);
    } else {
      endpoints_[guid] = EndpointInfo{topic, type, writer, guid};
    }
  }
  bool track_;
  WriterNames names_;
  mutable std::mutex mu_;
  std::map<std::string, EndpointInfo> endpoints_;
};

class FastParticipant final : public BackendParticipant {
 public:
  FastParticipant(const ParticipantOptions& options, const std::string& config_file, const Properties& security)
      : user_data_(WriterUserData(options.name)) {
    auto* factory = fdds::DomainParticipantFactory::get_instance();
    listener_ = std::make_unique<DiscoveryListener>(options.track_endpoints);
    fdds::DomainParticipantQos qos = factory->get_default_participant_qos();
    std::string from = "";
    if (!config_file.empty()) {
      if (factory->load_XML_profiles_file(config_file) != RC::RETCODE_OK) {
        throw std::runtime_error("Fast DDS: cannot load XML profiles from " + config_file);
      }
      if (factory->get_participant_qos_from_profile(kParticipantProfile, qos) != RC::RETCODE_OK) {
        throw std::runtime_error("Fast DDS: no participant profile '" + std::string(kParticipantProfile) + "' in " +
                                 config_file);
      }
      from = " (profile '" + std::string(kParticipantProfile) + "' of " + config_file + ")";
    } else {
      qos.name(options.name);
    }
    for (const auto& [name, value] : security) qos.properties().properties().emplace_back(name, value);
    participant_ = factory->create_participant(options.domain_id, qos, listener_.get(), fdds::StatusMask::none());
    if (!participant_) {
      throw std::runtime_error("Fast DDS: cannot create a participant on domain " + std::to_string(options.domain_id) +
                               from + (security.empty() ? "" : " with DDS Security (see the log above)"));
    }
    publisher_ = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    if (!publisher_ || !subscriber_) throw std::runtime_error("Fast DDS: cannot create publisher/subscriber");
    waitset_.attach_condition(guard_);
  }

  ~FastParticipant() override {
    waitset_.detach_condition(guard_);
    participant_->delete_contained_entities();
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }

  fdds::Topic* GetTopic(const std::string& name, const std::string& dds_type) {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = topics_.find(name);
    if (it != topics_.end()) {
      if (it->second->get_type_name() != dds_type) {
        throw std::runtime_error("topic '" + name + "' already has type " + it->second->get_type_name() +
                                 ", not " + dds_type);
      }
      return it->second;
    }
    const auto& ops = FindOps(dds_type);
    if (participant_->find_type(dds_type).empty()) {
      fdds::TypeSupport ts(ops.make());
      if (ts.register_type(participant_) != RC::RETCODE_OK) {
        throw std::runtime_error("Fast DDS: cannot register type " + dds_type);
      }
    }
    fdds::Topic* t = participant_->create_topic(name, dds_type, fdds::TOPIC_QOS_DEFAULT);
    if (!t) throw std::runtime_error("Fast DDS: cannot create topic " + name);
    topics_[name] = t;
    return t;
  }

  std::unique_ptr<BackendWriter> CreateWriter(const std::string& topic, const std::string& dds_type,
                                              const QosProfile& q) override {
    fdds::Topic* t = GetTopic(topic, dds_type);
    fdds::DataWriterQos qos = publisher_->get_default_datawriter_qos();
    qos.reliability().kind = q.writer_reliability == QosProfile::Reliability::kReliable
                                 ? fdds::RELIABLE_RELIABILITY_QOS
                                 : fdds::BEST_EFFORT_RELIABILITY_QOS;
    qos.reliability().max_blocking_time = Duration_t(0, 100000000);
    ApplyCommon(q, &qos.durability(), &qos.history(), &qos.deadline(), &qos.liveliness());
    // DDS-NOTES: the default 3 s heartbeat stalls the first data to a Cyclone reader.
    qos.reliable_writer_qos().times.heartbeatPeriod = Duration_t(0, 100000000);
    qos.data_sharing().off();
    qos.endpoint().history_memory_policy =
        eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    qos.user_data().data_vec(std::vector<eprosima::fastrtps::rtps::octet>(user_data_.begin(), user_data_.end()));
    fdds::DataWriter* w = publisher_->create_datawriter(t, qos, nullptr, fdds::StatusMask::none());
    if (!w) throw std::runtime_error("Fast DDS: cannot create a writer on " + topic);
    return std::make_unique<FastWriter>(publisher_, w);
  }

  std::unique_ptr<BackendReader> CreateReader(const std::string& topic, const std::string& dds_type,
                                              const QosProfile& q, AnyReader* owner) override {
    fdds::Topic* t = GetTopic(topic, dds_type);
    fdds::DataReaderQos qos = subscriber_->get_default_datareader_qos();
    qos.reliability().kind = q.reader_reliability == QosProfile::Reliability::kReliable
                                 ? fdds::RELIABLE_RELIABILITY_QOS
                                 : fdds::BEST_EFFORT_RELIABILITY_QOS;
    ApplyCommon(q, &qos.durability(), &qos.history(), &qos.deadline(), &qos.liveliness());
    qos.data_sharing().off();
    qos.endpoint().history_memory_policy =
        eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    fdds::DataReader* r = subscriber_->create_datareader(t, qos, nullptr, fdds::StatusMask::none());
    if (!r) throw std::runtime_error("Fast DDS: cannot create a reader on " + topic);
    fdds::DataReader* watch = q.watched_lease.count() > 0 ? CreateWatchReader(t, q.watched_lease) : nullptr;
    if (q.watched_lease.count() > 0 && !watch) {
      subscriber_->delete_datareader(r);
      throw std::runtime_error("Fast DDS: cannot create the liveliness reader on " + topic);
    }
    auto reader = std::make_unique<FastReader>(this, subscriber_, r, watch, listener_->names());
    fdds::StatusMask mask = fdds::StatusMask::data_available();
    mask << fdds::StatusMask::requested_deadline_missed() << fdds::StatusMask::liveliness_changed()
         << fdds::StatusMask::subscription_matched() << fdds::StatusMask::requested_incompatible_qos();
    Attach(r, mask, owner);
    if (watch) Attach(watch, fdds::StatusMask::liveliness_changed(), owner);
    return reader;
  }

  // A reader that takes no data and matches only writers offering `lease`
  // or shorter (iplan's own): a Fast DDS 2.9 reader tracks liveliness only
  // with a finite requested lease. Best effort, keep last 1, never taken:
  // the samples it is sent overwrite each other in its history.
  fdds::DataReader* CreateWatchReader(fdds::Topic* t, std::chrono::nanoseconds lease) {
    fdds::DataReaderQos qos = subscriber_->get_default_datareader_qos();
    qos.reliability().kind = fdds::BEST_EFFORT_RELIABILITY_QOS;
    qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
    qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    qos.history().depth = 1;
    qos.liveliness().kind = fdds::AUTOMATIC_LIVELINESS_QOS;
    qos.liveliness().lease_duration = ToDuration(lease);
    qos.data_sharing().off();
    qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    return subscriber_->create_datareader(t, qos, nullptr, fdds::StatusMask::none());
  }

  void Attach(fdds::DataReader* r, const fdds::StatusMask& mask, AnyReader* owner) {
    fdds::StatusCondition& cond = r->get_statuscondition();
    cond.set_enabled_statuses(mask);
    {
      std::lock_guard<std::mutex> lock(mu_);
      owners_[r] = owner;
    }
    waitset_.attach_condition(cond);
  }

  void DetachReader(fdds::DataReader* r) {
    waitset_.detach_condition(r->get_statuscondition());
    std::lock_guard<std::mutex> lock(mu_);
    owners_.erase(r);
  }

  void Wait(std::chrono::nanoseconds timeout, std::vector<AnyReader*>* ready) override {
    ready->clear();
    fdds::ConditionSeq active;
    const RC rc = waitset_.wait(active, ToDuration(timeout.count() > 0 ? timeout : std::chrono::nanoseconds(1)));
    if (rc != RC::RETCODE_OK) return;
    std::lock_guard<std::mutex> lock(mu_);
    for (fdds::Condition* c : active) {
      if (c == &guard_) {
        guard_.set_trigger_value(false);
        continue;
      }
      auto* sc = dynamic_cast<fdds::StatusCondition*>(c);
      if (!sc) continue;
      auto it = owners_.find(static_cast<fdds::DataReader*>(sc->get_entity()));
      if (it != owners_.end()) ready->push_back(it->second);
    }
  }

  void Wake() override { guard_.set_trigger_value(true); }

  std::vector<EndpointInfo> Endpoints() const override {
    return listener_->Endpoints();
  }

  fdds::Subscriber* subscriber() { return subscriber_; }

 private:
  std::string user_data_;
  std::unique_ptr<DiscoveryListener> listener_;
  fdds::DomainParticipant* participant_ = nullptr;
  fdds::Publisher* publisher_ = nullptr;
  fdds::Subscriber* subscriber_ = nullptr;
  fdds::WaitSet waitset_;
  fdds::GuardCondition guard_;
  std::mutex mu_;
  std::unordered_map<std::string, fdds::Topic*> topics_;
  std::unordered_map<fdds::DataReader*, AnyReader*> owners_;
};

FastReader::~FastReader() {
  owner_->DetachReader(reader_);
  subscriber_->delete_datareader(reader_);
  if (watch_) {
    owner_->DetachReader(watch_);
    subscriber_->delete_datareader(watch_);
  }
}

}  // namespace

std::unique_ptr<BackendParticipant> CreateFastDdsParticipant(const ParticipantOptions& options,
                                                             const std::string& config_file,
                                                             const Properties& security) {
  return std::make_unique<FastParticipant>(options, config_file, security);
}

}  // namespace iplan::dds::internal
