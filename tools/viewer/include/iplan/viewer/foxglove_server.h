// One HTTP + WebSocket server on one port: serves the viewer's static page
// (files under a web root) over HTTP, and speaks the Foxglove WebSocket
// protocol (subprotocol "foxglove.websocket.v1", JSON message encoding) on
// the same port, so the page and a user's Foxglove app connect the same way.
//
// websocketpp and asio stay inside foxglove_server.cc. The server runs on a
// thread of its own; every public method is thread-safe. A client that does
// not keep up (more than `max_buffered_bytes` queued) misses messages, which
// are counted, rather than slowing the caller; the socket's own send buffer
// is kept small too, so that what waits for a slow client is bounded by
// these two sizes and a page that cannot keep up (software rendering on a
// busy machine) gets recent messages, not ever older ones. Channels marked
// not droppable (small status channels) are always sent.
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
  /// Bytes queued for a client above which its droppable messages are dropped.
  std::size_t max_buffered_bytes = 256u << 10;
  /// SO_SNDBUF of each client's socket (0: the kernel's autotuned default, MBs on loopback).
  int socket_send_buffer_bytes = 64 << 10;
};

struct Channel {
  std::string topic;        ///< e.g. "/joint_states"
  std::string schema_name;  ///< e.g. "sensor_msgs/msg/JointState", "foxglove.SceneUpdate"
  std::string schema;       ///< JSON Schema text
  std::string encoding = "json";
  bool droppable = true;  ///< false: sent even to a client that is behind (keep such channels small)
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
