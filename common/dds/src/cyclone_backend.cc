// Cyclone DDS 0.10 backend: idlc C structs through the C API, one wait set
// per participant.
#include <atomic>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <stdexcept>
#include <unordered_map>

#include <dds/dds.h>

#include "backend.h"
#include "cyclone_convert.h"

namespace iplan::dds::internal {
namespace {

std::string Err(const std::string& what, dds_return_t rc) {
  return "Cyclone DDS: " + what + ": " + dds_strretcode(rc);
}

const cyclone_gen::CycloneTypeOps& FindOps(const std::string& dds_type) {
  for (const auto& ops : cyclone_gen::AllCycloneTypes()) {
    if (dds_type == ops.dds_name) return ops;
  }
  throw std::runtime_error("Cyclone DDS: no type support for '" + dds_type + "'");
}

// Cyclone's log on stderr, as its default sink writes it, one line per
// message, with one addition: the first handshake of the process that fails
// the Fast DDS way is explained. On Debian's builds a Cyclone participant
// cannot answer a Fast DDS one's handshake request (it cannot read the
// Diffie-Hellman key in it) and says only "Begin handshake reply failed:
// Failed to convert octet sequence to ASN1 integer", once a second, while
// the two never match (docs/dds.md, "Mixed vendors: what fails").
void LogSink(void*, const dds_log_data_t* d) {
  std::fwrite(d->message - d->hdrsize, 1, d->hdrsize + d->size, stderr);
  if (d->size == 0 || d->message[d->size - 1] != '\n') std::fputc('\n', stderr);
  static std::atomic<bool> explained{false};
  const std::string text(d->message, d->size);
  if (text.find("andshake") != std::string::npos && text.find("ASN1 integer") != std::string::npos &&
      !explained.exchange(true)) {
    std::fprintf(stderr,
                 "iplan: the DDS Security handshake above failed the way Debian's Fast DDS 2.9 and Cyclone DDS 0.10 "
                 "fail with each other (Cyclone cannot read the Diffie-Hellman key of a Fast DDS handshake "
                 "request): that participant runs Fast DDS and the two will never match. Run one DDS vendor on "
                 "every computer of a secured cell (IPLAN_DDS), or both unsecured on purpose (--insecure); "
                 "docs/dds.md, \"Mixed vendors: what fails\"\n");
  }
  std::fflush(stderr);
}

dds_duration_t ToDuration(std::chrono::nanoseconds ns) {
  return ns.count() <= 0 ? DDS_INFINITY : static_cast<dds_duration_t>(ns.count());
}

// QoS for one side of a topic. Cyclone's transient-local writers need the
// durability-service history as deep as the writer history (DDS-NOTES).
dds_qos_t* MakeQos(const QosProfile& q, bool writer) {
  dds_qos_t* qos = dds_create_qos();
  const auto rel = writer ? q.writer_reliability : q.reader_reliability;
  dds_qset_reliability(qos,
                       rel == QosProfile::Reliability::kReliable ? DDS_RELIABILITY_RELIABLE
                                                                 : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_MSECS(100));
  if (q.durability == QosProfile::Durability::kTransientLocal) {
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_durability_service(qos, 0, DDS_HISTORY_KEEP_LAST, q.depth, DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  } else {
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  }
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, q.depth);
  dds_qset_deadline(qos, ToDuration(q.deadline));
  dds_qset_liveliness(qos, DDS_LIVELINESS_AUTOMATIC, ToDuration(q.liveliness_lease));
  // @final types: XCDR1, the representation Fast CDR 1.x speaks.
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  return qos;
}

class CycloneWriter final : public BackendWriter {
 public:
  CycloneWriter(const cyclone_gen::CycloneTypeOps& ops, dds_entity_t w)
      : ops_(ops), writer_(w),
        sample_(new std::max_align_t[(ops.vendor_size + sizeof(std::max_align_t) - 1) /
                                     sizeof(std::max_align_t)]) {}
  ~CycloneWriter() override { dds_delete(writer_); }
  bool Write(const void* plain, std::string* error) override {
    std::lock_guard<std::mutex> lock(mu_);
    std::memset(sample_.get(), 0, ops_.vendor_size);
    arena_.Clear();
    ops_.to_vendor(plain, sample_.get(), arena_);
    const dds_return_t rc = dds_write(writer_, sample_.get());
    arena_.Clear();
    if (rc < 0) {
      if (error) *error = Err("dds_write", rc);
      return false;
    }
    return true;
  }
  int MatchedReaders() const override {
    dds_publication_matched_status_t s;
    if (dds_get_publication_matched_status(writer_, &s) < 0) return 0;
    return static_cast<int>(s.current_count);
  }
  bool WaitForAcknowledgments(std::chrono::nanoseconds timeout) override {
    return dds_wait_for_acks(writer_, ToDuration(timeout)) == DDS_RETCODE_OK;
  }

 private:
  const cyclone_gen::CycloneTypeOps& ops_;
  dds_entity_t writer_;
  std::mutex mu_;
  std::unique_ptr<std::max_align_t[]> sample_;
  cyclone_gen::Arena arena_;
};

class CycloneReader final : public BackendReader {
 public:
  CycloneReader(const cyclone_gen::CycloneTypeOps& ops, dds_entity_t r) : ops_(ops), reader_(r) {}
  // The writer's announced participant name, looked up once per matched
  // writer (a miss is not cached: discovery data may still be on its way).
  const std::string& WriterName(dds_instance_handle_t h) {
    auto it = names_.find(h);
    if (it != names_.end()) return it->second;
    dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(reader_, h);
    std::string name;
    if (e) {
      void* ud = nullptr;
      size_t sz = 0;
      if (e->qos && dds_qget_userdata(e->qos, &ud, &sz)) {
        name = NameFromUserData(static_cast<const unsigned char*>(ud), sz);
        dds_free(ud);
      }
      dds_builtintopic_free_endpoint(e);
    }
    if (name.empty()) {
      static const std::string kNone;
      return kNone;
    }
    if (names_.size() > 4096) names_.clear();  // bounded: writers come and go
    return names_.emplace(h, std::move(name)).first->second;
  }
  ~CycloneReader() override { dds_delete(reader_); }
  bool Take(void* plain, SampleInfo* info) override {
    // Clear DATA_AVAILABLE before taking: a sample that arrives after this
    // sets it again, so the wait set never misses one.
    uint32_t status = 0;
    dds_take_status(reader_, &status, DDS_DATA_AVAILABLE_STATUS);
    for (;;) {
      void* samples[1] = {nullptr};
      dds_sample_info_t si;
      const dds_return_t n = dds_take(reader_, samples, &si, 1, 1);
      if (n <= 0) return false;
      const bool valid = si.valid_data;
      if (valid) {
        ops_.from_vendor(samples[0], plain);
        info->source_timestamp_ns = si.source_timestamp;
        info->reception_ns = NowNs();
        info->writer_id = HashBytes(reinterpret_cast<const unsigned char*>(&si.publication_handle),
                                    sizeof(si.publication_handle));
        info->writer_name = WriterName(si.publication_handle);
      }
      dds_return_loan(reader_, samples, n);
      if (valid) return true;
    }
  }
  void TakeEvents(std::vector<ReaderEvent>* events) override {
    uint32_t st = 0;
    dds_get_status_changes(reader_, &st);
    if (st & DDS_REQUESTED_DEADLINE_MISSED_STATUS) {
      dds_requested_deadline_missed_status_t s;
      dds_get_requested_deadline_missed_status(reader_, &s);
      if (s.total_count_change > 0) {
        events->push_back({EventKind::kDeadlineMissed, static_cast<int32_t>(s.total_count),
                           s.total_count_change, 0});
      }
    }
    if (st & DDS_LIVELINESS_CHANGED_STATUS) {
      dds_liveliness_changed_status_t s;
      dds_get_liveliness_changed_status(reader_, &s);
      if (s.not_alive_count_change > 0 || s.alive_count_change < 0) {
        events->push_back({EventKind::kLivelinessLost, static_cast<int32_t>(s.not_alive_count),
                           std::max(s.not_alive_count_change, -s.alive_count_change),
                           static_cast<int32_t>(s.alive_count)});
      }
      if (s.alive_count_change > 0) {
        events->push_back({EventKind::kLivelinessRegained, static_cast<int32_t>(s.alive_count),
                           s.alive_count_change, static_cast<int32_t>(s.alive_count)});
      }
    }
    if (st & DDS_SUBSCRIPTION_MATCHED_STATUS) {
      dds_subscription_matched_status_t s;
      dds_get_subscription_matched_status(reader_, &s);
      if (s.current_count_change > 0) {
        events->push_back({EventKind::kMatched, static_cast<int32_t>(s.total_count),
                           s.current_count_change, static_cast<int32_t>(s.current_count)});
      } else if (s.current_count_change < 0) {
        events->push_back({EventKind::kUnmatched, static_cast<int32_t>(s.total_count),
                           -s.current_count_change, static_cast<int32_t>(s.current_count)});
      }
    }
    if (st & DDS_REQUESTED_INCOMPATIBLE_QOS_STATUS) {
      dds_requested_incompatible_qos_status_t s;
      dds_get_requested_incompatible_qos_status(reader_, &s);
      if (s.total_count_change > 0) {
        events->push_back({EventKind::kIncompatibleQos, static_cast<int32_t>(s.total_count),
                           s.total_count_change, static_cast<int32_t>(s.last_policy_id)});
      }
    }
  }
  int MatchedWriters() const override {
    dds_subscription_matched_status_t s;
    if (dds_get_subscription_matched_status(reader_, &s) < 0) return 0;
    return static_cast<int>(s.current_count);
  }

 private:
  const cyclone_gen::CycloneTypeOps& ops_;
  dds_entity_t reader_;
  std::unordered_map<dds_instance_handle_t, std::string> names_;
};

class CycloneParticipant final : public BackendParticipant {
 public:
  CycloneParticipant(const ParticipantOptions& options, const std::string& config_file, const Properties& security)
      : user_data_(WriterUserData(options.name)) {
    if (!config_file.empty()) {
      const std::string uri = "file://" + config_file;
      const dds_entity_t dom = dds_create_domain(static_cast<dds_domainid_t>(options.domain_id), uri.c_str());
      // PRECONDITION_NOT_MET: the domain already exists in this process (a
      // second participant); it keeps the configuration it was created with.
      if (dom < 0 && dom != DDS_RETCODE_PRECONDITION_NOT_MET) {
        throw std::runtime_error(Err("cannot create domain " + std::to_string(options.domain_id) +
                                     " with " + config_file, dom));
      }
      if (dom >= 0) domain_ = dom;
    }
    if (!security.empty()) {
      static std::once_flag sink;
      std::call_once(sink, [] { dds_set_log_sink(&LogSink, nullptr); });
    }
    dds_qos_t* pq = dds_create_qos();
    dds_qset_entity_name(pq, options.name.c_str());
    for (const auto& [name, value] : security) dds_qset_prop(pq, name.c_str(), value.c_str());
    participant_ = dds_create_participant(static_cast<dds_domainid_t>(options.domain_id), pq, nullptr);
    dds_delete_qos(pq);
    if (participant_ < 0) {
      throw std::runtime_error(Err("cannot create a participant on domain " + std::to_string(options.domain_id) +
                                       (security.empty() ? "" : " with DDS Security (see the log above)"),
                                   participant_));
    }
    waitset_ = dds_create_waitset(participant_);
    guard_ = dds_create_guardcondition(participant_);
    if (waitset_ < 0 || guard_ < 0) throw std::runtime_error("Cyclone DDS: cannot create the wait set");
    dds_waitset_attach(waitset_, guard_, 0);
    if (options.track_endpoints) {
      pub_reader_ = dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
      sub_reader_ = dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr);
    }
  }

  ~CycloneParticipant() override {
    dds_delete(participant_);
    if (domain_ > 0) dds_delete(domain_);
  }

  dds_entity_t GetTopic(const std::string& name, const std::string& dds_type) {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = topics_.find(name);
    if (it != topics_.end()) {
      if (it->second.second != dds_type) {
        throw std::runtime_error("topic '" + name + "' already has type " + it->second.second +
                                 ", not " + dds_type);
      }
      return it->second.first;
    }
    const auto& ops = FindOps(dds_type);
    const dds_entity_t t = dds_create_topic(participant_, ops.descriptor, name.c_str(), nullptr, nullptr);
    if (t < 0) throw std::runtime_error(Err("cannot create topic " + name, t));
    topics_[name] = {t, dds_type};
    return t;
  }

  std::unique_ptr<BackendWriter> CreateWriter(const std::string& topic, const std::string& dds_type,
                                              const QosProfile& q) override {
    const dds_entity_t t = GetTopic(topic, dds_type);
    dds_qos_t* qos = MakeQos(q, true);
    dds_qset_userdata(qos, user_data_.data(), user_data_.size());
    const dds_entity_t w = dds_create_writer(participant_, t, qos, nullptr);
    dds_delete_qos(qos);
    if (w < 0) throw std::runtime_error(Err("cannot create a writer on " + topic, w));
    return std::make_unique<CycloneWriter>(FindOps(dds_type), w);
  }

  std::unique_ptr<BackendReader> CreateReader(const std::string& topic, const std::string& dds_type,
                                              const QosProfile& q, AnyReader* owner) override {
    const dds_entity_t t = GetTopic(topic, dds_type);
    dds_qos_t* qos = MakeQos(q, false);
    const dds_entity_t r = dds_create_reader(participant_, t, qos, nullptr);
    dds_delete_qos(qos);
    if (r < 0) throw std::runtime_error(Err("cannot create a reader on " + topic, r));
    dds_set_status_mask(r, DDS_DATA_AVAILABLE_STATUS | DDS_REQUESTED_DEADLINE_MISSED_STATUS |
                               DDS_LIVELINESS_CHANGED_STATUS | DDS_SUBSCRIPTION_MATCHED_STATUS |
                               DDS_REQUESTED_INCOMPATIBLE_QOS_STATUS);
    dds_waitset_attach(waitset_, r, reinterpret_cast<dds_attach_t>(owner));
    return std::make_unique<CycloneReader>(FindOps(dds_type), r);
  }

  void Wait(std::chrono::nanoseconds timeout, std::vector<AnyReader*>* ready) override {
    ready->clear();
    dds_attach_t xs[64];
    const dds_return_t n = dds_waitset_wait(waitset_, xs, 64, ToDuration(timeout.count() > 0 ? timeout : std::chrono::nanoseconds(1)));
    for (dds_return_t i = 0; i < n && i < 64; ++i) {
      if (xs[i] == 0) {
        bool triggered = false;
        dds_take_guardcondition(guard_, &triggered);
        continue;
      }
      ready->push_back(reinterpret_cast<AnyReader*>(xs[i]));
    }
  }

  void Wake() override { dds_set_guardcondition(guard_, true); }

  std::vector<EndpointInfo> Endpoints() const override {
    std::vector<EndpointInfo> out;
    for (const auto& [reader, is_writer] : {std::pair{pub_reader_, true}, std::pair{sub_reader_, false}}) {
      if (reader <= 0) continue;
      void* samples[256] = {nullptr};
      dds_sample_info_t infos[256];
      const dds_return_t n = dds_read_mask(reader, samples, infos, 256, 256,
                                           DDS_ANY_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ALIVE_INSTANCE_STATE);
      for (dds_return_t i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
        out.push_back(EndpointInfo{e->topic_name ? e->topic_name : "", e->type_name ? e->type_name : "",
                                   is_writer, HexGuid(e->key.v, 16)});
      }
      if (n > 0) dds_return_loan(reader, samples, n);
    }
    return out;
  }

 private:
  std::string user_data_;
  dds_entity_t domain_ = 0;
  dds_entity_t participant_ = 0;
  dds_entity_t waitset_ = 0;
  dds_entity_t guard_ = 0;
  dds_entity_t pub_reader_ = 0;
  dds_entity_t sub_reader_ = 0;
  std::mutex mu_;
  std::unordered_map<std::string, std::pair<dds_entity_t, std::string>> topics_;
};

}  // namespace

std::unique_ptr<BackendParticipant> CreateCycloneParticipant(const ParticipantOptions& options,
                                                             const std::string& config_file,
                                                             const Properties& security) {
  return std::make_unique<CycloneParticipant>(options, config_file, security);
}

}  // namespace iplan::dds::internal
