#include "lampnav/ros/participant.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <atomic>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <map>
#include <mutex>
#include <vector>

#include "lampnav/core/error.hpp"

namespace lampnav::ros {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::SerializedPayload_t;

std::string dds_topic(const std::string& t) {
  auto bad = [&](const std::string& why) {
    throw InputError({"", "topic", t}, "not a ROS 2 topic name: " + why);
  };
  if (t.size() < 2 || t[0] != '/') bad("it must start with / and name something");
  if (t.back() == '/') bad("it must not end with /");
  for (std::size_t k = 0; k < t.size(); ++k) {
    const char c = t[k];
    if (c == '/' && k > 0 && t[k - 1] == '/') bad("it holds //");
    if (c != '/' && c != '_' && !std::isalnum(static_cast<unsigned char>(c)))
      bad(std::string("character '") + c + "' (letters, digits, _ and / only)");
    if (std::isdigit(static_cast<unsigned char>(c)) && t[k - 1] == '/')
      bad("a part of it starts with a digit");
  }
  return "rt" + t;
}

std::string dds_type(const std::string& ros_type) {
  const auto p = ros_type.find("/msg/");
  if (p == std::string::npos || p == 0 || p + 5 >= ros_type.size())
    throw InputError({"", "type", ros_type}, "not a ROS 2 message type (package/msg/Name)");
  return ros_type.substr(0, p) + "::msg::dds_::" + ros_type.substr(p + 5) + "_";
}

int domain_from_environment() {
  const char* v = std::getenv("ROS_DOMAIN_ID");
  if (!v || !*v) return 0;
  char* end = nullptr;
  const long d = std::strtol(v, &end, 10);
  if (*end != '\0' || d < 0 || d > 232)
    throw InputError({"", "environment", "ROS_DOMAIN_ID"},
                     std::string("\"") + v + "\" is not a domain id (0 to 232)");
  return static_cast<int>(d);
}

namespace {

// A message type Fast DDS carries as its CDR bytes, registered under the ROS 2 type name. The
// bytes are io's to write and read; the payload is sized per sample.
class CdrBytes : public dds::TopicDataType {
 public:
  explicit CdrBytes(const std::string& name) {
    setName(name.c_str());
    m_typeSize = 4 + 4096;  // a first allocation; samples grow their payload as needed
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, SerializedPayload_t* payload) override {
    const auto& s = *static_cast<const std::string*>(data);
    if (s.size() < 4 || s.size() > payload->max_size) return false;
    std::memcpy(payload->data, s.data(), s.size());
    payload->length = static_cast<std::uint32_t>(s.size());
    payload->encapsulation = s[1] == 1 ? CDR_LE : CDR_BE;
    return true;
  }
  bool deserialize(SerializedPayload_t* payload, void* data) override {
    static_cast<std::string*>(data)->assign(reinterpret_cast<const char*>(payload->data),
                                            payload->length);
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<std::uint32_t>(static_cast<std::string*>(data)->size()); };
  }
  void* createData() override { return new std::string(); }
  void deleteData(void* data) override { delete static_cast<std::string*>(data); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

void apply(Qos q, bool reader, dds::ReliabilityQosPolicy& reliability,
           dds::DurabilityQosPolicy& durability, dds::HistoryQosPolicy& history) {
  reliability.kind =
      q == Qos::sensor_data ? dds::BEST_EFFORT_RELIABILITY_QOS : dds::RELIABLE_RELIABILITY_QOS;
  durability.kind =
      q == Qos::tf_static ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  history.kind = dds::KEEP_LAST_HISTORY_QOS;
  history.depth = q == Qos::sensor_data            ? 5
                  : q == Qos::state                ? 10
                  : q == Qos::tf_static && !reader ? 1
                                                   : 100;
}

class Listener : public dds::DataReaderListener {
 public:
  explicit Listener(std::function<void(Sample&&)> fn) : fn_(std::move(fn)) {}
  void on_data_available(dds::DataReader* reader) override {
    std::string bytes;
    dds::SampleInfo info;
    while (reader->take_next_sample(&bytes, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      Sample s;
      s.cdr = std::move(bytes);
      s.arrival = Clock::now();
      s.sequence = ++count_;
      fn_(std::move(s));
      bytes.clear();
    }
  }
  void on_subscription_matched(dds::DataReader*,
                               const dds::SubscriptionMatchedStatus& status) override {
    matched_ = status.current_count;
  }
  int matched() const { return matched_; }

 private:
  std::function<void(Sample&&)> fn_;
  std::uint64_t count_ = 0;
  std::atomic<int> matched_{0};
};

class DdsWriter : public Writer {
 public:
  explicit DdsWriter(dds::DataWriter* w) : w_(w) {}
  bool write(const std::string& cdr) override { return w_->write(const_cast<std::string*>(&cdr)); }
  int matched() const override {
    dds::PublicationMatchedStatus s;
    w_->get_publication_matched_status(s);
    return s.current_count;
  }

 private:
  dds::DataWriter* w_;
};

}  // namespace

struct Participant::Impl {
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  std::map<std::string, dds::TypeSupport> types;  // by DDS type name
  std::map<std::string, dds::Topic*> topics;      // by DDS topic name
  std::vector<std::unique_ptr<Listener>> listeners;
  std::map<std::string, Listener*> listener_of;  // by ROS topic
  std::vector<std::unique_ptr<DdsWriter>> writers;
  std::mutex mutex;

  dds::Topic* topic(const std::string& ros_topic, const std::string& ros_type) {
    const std::string name = dds_topic(ros_topic), type = dds_type(ros_type);
    if (!types.count(type)) {
      dds::TypeSupport ts(new CdrBytes(type));
      if (ts.register_type(participant) != ReturnCode_t::RETCODE_OK)
        throw JobFailed("DDS refused the type " + type);
      types.emplace(type, ts);
    }
    if (const auto it = topics.find(name); it != topics.end()) {
      if (it->second->get_type_name() != type)
        throw InputError({"", "topic", ros_topic},
                         "used with two types: " + it->second->get_type_name() + " and " + type);
      return it->second;
    }
    dds::Topic* t = participant->create_topic(name, type, dds::TOPIC_QOS_DEFAULT);
    if (!t) throw JobFailed("DDS refused the topic " + name);
    topics.emplace(name, t);
    return t;
  }
};

Participant::Participant(int domain, const ParticipantOptions& o)
    : impl_(std::make_unique<Impl>()) {
  if (domain < 0 || domain > 232)
    throw InputError({"", "option", "domain"}, std::to_string(domain) + " is not 0 to 232");
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::DomainParticipantQos qos = factory->get_default_participant_qos();
  qos.name(o.name);
  if (!std::getenv("FASTRTPS_DEFAULT_PROFILES_FILE")) {
    auto shm = std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>();
    shm->segment_size(o.shm_segment_bytes);
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->sendBufferSize = udp->receiveBufferSize = o.socket_buffer_bytes;
    qos.transport().use_builtin_transports = false;
    qos.transport().user_transports = {shm, udp};
  }
  impl_->participant = factory->create_participant(domain, qos);
  if (!impl_->participant)
    throw JobFailed("DDS could not join domain " + std::to_string(domain) +
                    " (no usable network interface or transport)");
  impl_->publisher = impl_->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  impl_->subscriber = impl_->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (!impl_->publisher || !impl_->subscriber) throw JobFailed("DDS refused a publisher");
}

Participant::~Participant() {
  if (!impl_->participant) return;
  // Readers first, so no listener runs while the rest goes.
  impl_->participant->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(impl_->participant);
}

void Participant::subscribe(const std::string& ros_topic, const std::string& ros_type, Qos q,
                            std::function<void(Sample&&)> on_sample) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  dds::Topic* t = impl_->topic(ros_topic, ros_type);
  dds::DataReaderQos qos = impl_->subscriber->get_default_datareader_qos();
  apply(q, true, qos.reliability(), qos.durability(), qos.history());
  qos.endpoint().history_memory_policy =
      eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  auto listener = std::make_unique<Listener>(std::move(on_sample));
  dds::DataReader* r = impl_->subscriber->create_datareader(t, qos, listener.get());
  if (!r) throw JobFailed("DDS refused a reader of " + ros_topic);
  impl_->listener_of[ros_topic] = listener.get();
  impl_->listeners.push_back(std::move(listener));
}

Writer& Participant::writer(const std::string& ros_topic, const std::string& ros_type, Qos q) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  dds::Topic* t = impl_->topic(ros_topic, ros_type);
  dds::DataWriterQos qos = impl_->publisher->get_default_datawriter_qos();
  apply(q, false, qos.reliability(), qos.durability(), qos.history());
  qos.endpoint().history_memory_policy =
      eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  qos.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;  // as rmw_fastrtps by default
  dds::DataWriter* w = impl_->publisher->create_datawriter(t, qos);
  if (!w) throw JobFailed("DDS refused a writer of " + ros_topic);
  impl_->writers.push_back(std::make_unique<DdsWriter>(w));
  return *impl_->writers.back();
}

int Participant::publishers_matched(const std::string& ros_topic) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  const auto it = impl_->listener_of.find(ros_topic);
  return it == impl_->listener_of.end() ? 0 : it->second->matched();
}

}  // namespace lampnav::ros
