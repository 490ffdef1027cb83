// One HTTP + WebSocket server on one port: serves the viewer's static page
// (files under a web root) over HTTP, and speaks the Foxglove WebSocket
// protocol (subprotocol "foxglove.websocket.v1", JSON message encoding) on
// the same port, so the page and a user's Foxglove app connect the same way.
//
// websocketpp and asio stay inside foxglove_server.cc. The server runs on a
// thread of its own; every public method is thread-safe. A client that does
// not keep up (more than `max_buffered_bytes` queued) misses messages, which
// are counted, rather than slowing the caller.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>

namespace iplan::viewer {

struct FoxgloveServerOptions {
  std::string bind = "127.0.0.1";  ///< address to listen on ("0.0.0.0": every interface)
  int port = 8080;                 ///< 0: any free port (see port())
  std::string web_root;            ///< folder of the static files; empty: no page
  std::string name = "iplan";      ///< serverInfo name
  /// Extra files served as-is: URL path (e.g. "/recording.mcap") -> file path.
  std::map<std::string, std::string> files;
  std::size_t max_buffered_bytes = 4u << 20;
};

struct Channel {
  std::string topic;        ///< e.g. "/joint_states"
  std::string schema_name;  ///< e.g. "sensor_msgs/msg/JointState", "foxglove.SceneUpdate"
  std::string schema;       ///< JSON Schema text
  std::string encoding = "json";
};

struct FoxgloveServerStats {
  uint64_t clients = 0;           ///< connected now
  uint64_t messages_sent = 0;     ///< message-data frames written
  uint64_t messages_dropped = 0;  ///< not sent: the client was too far behind
  uint64_t http_requests = 0;
  uint64_t bad_requests = 0;      ///< unparsable client messages, unknown paths
};

class FoxgloveServer {
 public:
  /// Listens and starts the server thread.
  /// @throws std::runtime_error when the address cannot be bound.
  explicit FoxgloveServer(FoxgloveServerOptions options);
  ~FoxgloveServer();  ///< closes every connection and joins the thread
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  /// The port listened on.
  int port() const;
  /// Advertises a channel to current and future clients; returns its id.
  uint32_t AddChannel(const Channel& channel);
  /// True when some client subscribes to `channel` (lets the caller skip work).
  bool HasSubscribers(uint32_t channel) const;
  /// Sends `payload` (JSON text) to every subscriber of `channel`, stamped
  /// `log_time_ns` (ns since the Unix epoch).
  void Publish(uint32_t channel, uint64_t log_time_ns, const std::string& payload);
  FoxgloveServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace iplan::viewer
