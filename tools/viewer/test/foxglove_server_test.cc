// FoxgloveServer against a real WebSocket client (websocketpp) over
// loopback: serverInfo and advertise on connect, the subprotocol required,
// subscribe, binary message frames with subscription id and log time, and the
// static page over HTTP on the same port.
#include "iplan/viewer/foxglove_server.h"

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

namespace iplan::viewer {
namespace {

using WsClient = websocketpp::client<websocketpp::config::asio_client>;
using namespace std::chrono_literals;

struct Client {
  WsClient c;
  std::thread t;
  websocketpp::connection_hdl h;
  std::mutex mu;
  std::condition_variable cv;
  std::vector<std::string> texts, binaries;
  bool open = false, failed = false;

  Client(int port, const std::string& subprotocol) {
    c.clear_access_channels(websocketpp::log::alevel::all);
    c.clear_error_channels(websocketpp::log::elevel::all);
    c.init_asio();
    c.set_open_handler([this](auto) { Set([&] { open = true; }); });
    c.set_fail_handler([this](auto) { Set([&] { failed = true; }); });
    c.set_message_handler([this](auto, WsClient::message_ptr m) {
      Set([&] {
        (m->get_opcode() == websocketpp::frame::opcode::text ? texts : binaries).push_back(m->get_payload());
      });
    });
    websocketpp::lib::error_code ec;
    auto con = c.get_connection("ws://127.0.0.1:" + std::to_string(port) + "/", ec);
    if (!subprotocol.empty()) con->add_subprotocol(subprotocol);
    h = con->get_handle();
    c.connect(con);
    t = std::thread([this] { c.run(); });
  }
  ~Client() {
    c.stop();
    t.join();
  }
  template <class F>
  void Set(F f) {
    std::lock_guard<std::mutex> l(mu);
    f();
    cv.notify_all();
  }
  bool WaitFor(const std::function<bool()>& pred) {
    std::unique_lock<std::mutex> l(mu);
    return cv.wait_for(l, 5s, pred);
  }
  void Send(const nlohmann::json& j) {
    websocketpp::lib::error_code ec;
    c.send(h, j.dump(), websocketpp::frame::opcode::text, ec);
    ASSERT_FALSE(ec) << ec.message();
  }
};

TEST(FoxgloveServer, AdvertisesSubscribesAndSendsFrames) {
  FoxgloveServerOptions o;
  o.port = 0;
  FoxgloveServer server(o);
  ASSERT_GT(server.port(), 0);
  const uint32_t a = server.AddChannel({"/a", "pkg/msg/A", "{}"});
  const uint32_t b = server.AddChannel({"/b", "pkg/msg/B", "{}"});
  Client client(server.port(), "foxglove.websocket.v1");
  ASSERT_TRUE(client.WaitFor([&] { return client.texts.size() >= 2; }));
  const auto info = nlohmann::json::parse(client.texts[0]);
  EXPECT_EQ(info["op"], "serverInfo");
  const auto adv = nlohmann::json::parse(client.texts[1]);
  ASSERT_EQ(adv["op"], "advertise");
  ASSERT_EQ(adv["channels"].size(), 2u);
  EXPECT_EQ(adv["channels"][1]["topic"], "/b");
  EXPECT_EQ(adv["channels"][1]["encoding"], "json");
  EXPECT_FALSE(server.HasSubscribers(b));

  client.Send({{"op", "subscribe"}, {"subscriptions", {{{"id", 7}, {"channelId", b}}}}});
  for (int i = 0; i < 100 && !server.HasSubscribers(b); ++i) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(server.HasSubscribers(b));
  server.Publish(a, 1, "{\"not\":\"subscribed\"}");
  server.Publish(b, 0x0102030405060708ull, "{\"x\":1}");
  ASSERT_TRUE(client.WaitFor([&] { return !client.binaries.empty(); }));
  const std::string f = client.binaries[0];
  ASSERT_EQ(f.size(), 13u + 7u);
  EXPECT_EQ(f[0], 1);  // message data
  EXPECT_EQ(f[1], 7);  // subscription id, little endian
  EXPECT_EQ(f[5], 0x08);
  EXPECT_EQ(f[12], 0x01);
  EXPECT_EQ(f.substr(13), "{\"x\":1}");

  // A bad client message gets a warning status, and the server goes on.
  client.Send({{"op", "subscribe"}, {"subscriptions", {{{"id", 8}, {"channelId", 99}}}}});
  ASSERT_TRUE(client.WaitFor([&] { return client.texts.size() >= 3; }));
  EXPECT_EQ(nlohmann::json::parse(client.texts[2])["op"], "status");
  EXPECT_EQ(server.stats().bad_requests, 1u);
  EXPECT_EQ(client.binaries.size(), 1u);
}

TEST(FoxgloveServer, RefusesClientsWithoutTheSubprotocol) {
  FoxgloveServerOptions o;
  o.port = 0;
  FoxgloveServer server(o);
  Client client(server.port(), "");
  ASSERT_TRUE(client.WaitFor([&] { return client.failed || client.open; }));
  EXPECT_TRUE(client.failed);
  EXPECT_FALSE(client.open);
}

TEST(FoxgloveServer, RefusesAPortInUse) {
  FoxgloveServerOptions o;
  o.port = 0;
  FoxgloveServer first(o);
  o.port = first.port();
  EXPECT_THROW(FoxgloveServer second(o), std::runtime_error);
}

}  // namespace
}  // namespace iplan::viewer
