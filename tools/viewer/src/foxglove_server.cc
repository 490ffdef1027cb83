#include "iplan/viewer/foxglove_server.h"

#include <atomic>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace iplan::viewer {
namespace {

using WsServer = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;
constexpr const char* kSubprotocol = "foxglove.websocket.v1";
constexpr uint8_t kMessageData = 0x01;  // server binary opcode

std::string ContentType(const std::string& path) {
  static const std::pair<const char*, const char*> kTypes[] = {
      {".html", "text/html; charset=utf-8"}, {".js", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},   {".json", "application/json"},
      {".png", "image/png"},                 {".svg", "image/svg+xml"},
      {".mcap", "application/octet-stream"}};
  for (const auto& [ext, type] : kTypes) {
    const std::string e(ext);
    if (path.size() >= e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0) return type;
  }
  return "application/octet-stream";
}

bool ReadWhole(const std::string& path, std::string* out) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return false;
  std::ostringstream s;
  s << f.rdbuf();
  *out = s.str();
  return true;
}

void AppendLe(std::string* s, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) s->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

}  // namespace

struct FoxgloveServer::Impl {
  struct Client {
    std::map<uint32_t, uint32_t> subscriptions;  // subscription id -> channel id
  };

  FoxgloveServerOptions o;
  WsServer server;
  std::thread thread;
  mutable std::mutex mu;  // channels, clients
  std::vector<Channel> channels;  // channel id = index + 1
  std::map<Hdl, Client, std::owner_less<Hdl>> clients;
  std::map<uint32_t, int> subscribers;  // channel id -> subscriptions
  std::atomic<uint64_t> sent{0}, dropped{0}, http{0}, bad{0};
  int port = 0;

  nlohmann::json Advertisement(uint32_t id) const {
    const Channel& c = channels[id - 1];
    return {{"id", id}, {"topic", c.topic}, {"encoding", c.encoding}, {"schemaName", c.schema_name},
            {"schema", c.schema}, {"schemaEncoding", "jsonschema"}};
  }

  void SendText(Hdl h, const nlohmann::json& j) {
    websocketpp::lib::error_code ec;
    server.send(h, j.dump(), websocketpp::frame::opcode::text, ec);
  }

  void SendStatus(Hdl h, int level, const std::string& message) {
    SendText(h, {{"op", "status"}, {"level", level}, {"message", message}});
  }

  void OnHttp(Hdl h) {
    ++http;
    auto con = server.get_con_from_hdl(h);
    std::string path = con->get_resource();
    path = path.substr(0, path.find('?'));
    std::string file;
    if (auto it = o.files.find(path); it != o.files.end()) {
      file = it->second;
    } else if (!o.web_root.empty() && path.find("..") == std::string::npos) {
      file = o.web_root + (path == "/" ? std::string("/index.html") : path);
    }
    std::string body;
    if (file.empty() || !ReadWhole(file, &body)) {
      ++bad;
      con->set_status(websocketpp::http::status_code::not_found);
      con->set_body("not found: " + path + "\n");
      return;
    }
    con->set_status(websocketpp::http::status_code::ok);
    con->append_header("Content-Type", ContentType(file));
    con->append_header("Cache-Control", "no-store");
    con->set_body(std::move(body));
  }

  bool OnValidate(Hdl h) {
    auto con = server.get_con_from_hdl(h);
    for (const auto& p : con->get_requested_subprotocols()) {
      if (p == kSubprotocol) {
        con->select_subprotocol(kSubprotocol);
        return true;
      }
    }
    ++bad;
    spdlog::warn("viewer: refused a WebSocket client without subprotocol {}", kSubprotocol);
    return false;
  }

  void OnOpen(Hdl h) {
    nlohmann::json adv = {{"op", "advertise"}, {"channels", nlohmann::json::array()}};
    {
      std::lock_guard<std::mutex> lock(mu);
      clients[h] = Client{};
      for (uint32_t id = 1; id <= channels.size(); ++id) adv["channels"].push_back(Advertisement(id));
    }
    SendText(h, {{"op", "serverInfo"}, {"name", o.name}, {"capabilities", nlohmann::json::array()},
                 {"supportedEncodings", {"json"}}, {"metadata", nlohmann::json::object()}});
    SendText(h, adv);
  }

  void OnClose(Hdl h) {
    std::lock_guard<std::mutex> lock(mu);
    auto it = clients.find(h);
    if (it == clients.end()) return;
    for (const auto& [sub, ch] : it->second.subscriptions) --subscribers[ch];
    clients.erase(it);
  }

  void OnMessage(Hdl h, WsServer::message_ptr m) {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(m->get_payload());
      const std::string op = j.at("op").get<std::string>();
      std::lock_guard<std::mutex> lock(mu);
      Client& c = clients[h];
      if (op == "subscribe") {
        for (const auto& s : j.at("subscriptions")) {
          const uint32_t id = s.at("id").get<uint32_t>(), ch = s.at("channelId").get<uint32_t>();
          if (ch == 0 || ch > channels.size() || c.subscriptions.count(id)) throw std::invalid_argument("bad subscription");
          c.subscriptions[id] = ch;
          ++subscribers[ch];
        }
      } else if (op == "unsubscribe") {
        for (const auto& s : j.at("subscriptionIds")) {
          auto it = c.subscriptions.find(s.get<uint32_t>());
          if (it == c.subscriptions.end()) continue;
          --subscribers[it->second];
          c.subscriptions.erase(it);
        }
      } else {
        throw std::invalid_argument("unsupported op '" + op + "'");
      }
    } catch (const std::exception& e) {
      ++bad;
      SendStatus(h, 1, std::string("iplan viewer: ") + e.what());
    }
  }

  // On the server thread.
  void Deliver(uint32_t channel, const std::string& frame_tail, uint64_t t_ns) {
    std::lock_guard<std::mutex> lock(mu);
    for (auto& [h, c] : clients) {
      for (const auto& [sub, ch] : c.subscriptions) {
        if (ch != channel) continue;
        websocketpp::lib::error_code ec;
        auto con = server.get_con_from_hdl(h, ec);
        if (ec || (channels[channel - 1].droppable && con->get_buffered_amount() > o.max_buffered_bytes)) {
          ++dropped;
          continue;
        }
        std::string frame;
        frame.reserve(13 + frame_tail.size());
        frame.push_back(static_cast<char>(kMessageData));
        AppendLe(&frame, sub, 4);
        AppendLe(&frame, t_ns, 8);
        frame += frame_tail;
        server.send(h, frame, websocketpp::frame::opcode::binary, ec);
        if (ec) ++dropped;
        else ++sent;
      }
    }
  }
};

FoxgloveServer::FoxgloveServer(FoxgloveServerOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.o = std::move(options);
  s.server.clear_access_channels(websocketpp::log::alevel::all);
  s.server.clear_error_channels(websocketpp::log::elevel::all);
  s.server.init_asio();
  s.server.set_reuse_addr(true);
  s.server.set_http_handler([&s](Hdl h) { s.OnHttp(h); });
  s.server.set_validate_handler([&s](Hdl h) { return s.OnValidate(h); });
  s.server.set_open_handler([&s](Hdl h) { s.OnOpen(h); });
  s.server.set_socket_init_handler([&s](Hdl, asio::ip::tcp::socket& socket) {
    asio::error_code sec;
    if (s.o.socket_send_buffer_bytes > 0) socket.set_option(asio::socket_base::send_buffer_size(s.o.socket_send_buffer_bytes), sec);
    socket.set_option(asio::ip::tcp::no_delay(true), sec);
  });
  s.server.set_close_handler([&s](Hdl h) { s.OnClose(h); });
  s.server.set_fail_handler([&s](Hdl h) { s.OnClose(h); });
  s.server.set_message_handler([&s](Hdl h, WsServer::message_ptr m) { s.OnMessage(h, m); });
  websocketpp::lib::error_code ec;
  asio::error_code aec;
  const auto address = asio::ip::make_address(s.o.bind, aec);
  if (aec) throw std::runtime_error("bad bind address '" + s.o.bind + "': " + aec.message());
  s.server.listen(asio::ip::tcp::endpoint(address, static_cast<unsigned short>(s.o.port)), ec);
  if (ec) throw std::runtime_error("cannot listen on " + s.o.bind + ":" + std::to_string(s.o.port) + ": " + ec.message());
  s.server.start_accept(ec);
  if (ec) throw std::runtime_error("cannot accept on port " + std::to_string(s.o.port) + ": " + ec.message());
  s.port = s.server.get_local_endpoint(aec).port();
  s.thread = std::thread([&s] {
    try {
      s.server.run();
    } catch (const std::exception& e) {
      spdlog::error("viewer: server thread stopped: {}", e.what());
    }
  });
}

FoxgloveServer::~FoxgloveServer() {
  Impl& s = *impl_;
  asio::post(s.server.get_io_service(), [&s] {
    websocketpp::lib::error_code ec;
    s.server.stop_listening(ec);
    std::lock_guard<std::mutex> lock(s.mu);
    for (auto& [h, c] : s.clients) s.server.close(h, websocketpp::close::status::going_away, "viewer stopped", ec);
  });
  // Give the close frames a moment, then stop the loop.
  asio::steady_timer timer(s.server.get_io_service(), std::chrono::milliseconds(200));
  timer.async_wait([&s](const asio::error_code&) { s.server.stop(); });
  if (s.thread.joinable()) s.thread.join();
}

int FoxgloveServer::port() const { return impl_->port; }

uint32_t FoxgloveServer::AddChannel(const Channel& channel) {
  Impl& s = *impl_;
  uint32_t id;
  {
    std::lock_guard<std::mutex> lock(s.mu);
    s.channels.push_back(channel);
    id = static_cast<uint32_t>(s.channels.size());
  }
  asio::post(s.server.get_io_service(), [&s, id] {
    nlohmann::json adv;
    std::vector<Hdl> hs;
    {
      std::lock_guard<std::mutex> lock(s.mu);
      adv = {{"op", "advertise"}, {"channels", {s.Advertisement(id)}}};
      for (auto& [h, c] : s.clients) hs.push_back(h);
    }
    for (auto& h : hs) s.SendText(h, adv);
  });
  return id;
}

bool FoxgloveServer::HasSubscribers(uint32_t channel) const {
  std::lock_guard<std::mutex> lock(impl_->mu);
  auto it = impl_->subscribers.find(channel);
  return it != impl_->subscribers.end() && it->second > 0;
}

void FoxgloveServer::Publish(uint32_t channel, uint64_t log_time_ns, const std::string& payload) {
  Impl& s = *impl_;
  asio::post(s.server.get_io_service(), [&s, channel, log_time_ns, payload] { s.Deliver(channel, payload, log_time_ns); });
}

FoxgloveServerStats FoxgloveServer::stats() const {
  const Impl& s = *impl_;
  FoxgloveServerStats st;
  {
    std::lock_guard<std::mutex> lock(s.mu);
    st.clients = s.clients.size();
  }
  st.messages_sent = s.sent;
  st.messages_dropped = s.dropped;
  st.http_requests = s.http;
  st.bad_requests = s.bad;
  return st;
}

}  // namespace iplan::viewer
