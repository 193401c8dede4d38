// FoxgloveServer (viewer/foxglove_server.h) with a websocketpp client on loopback: the protocol's
// opening messages, a subscription getting the latched message, and a client that never reads
// having messages dropped and counted while the publisher never waits. Plus the --serve parser.
#include "viewer/foxglove_server.h"

#define ASIO_STANDALONE
#define _WEBSOCKETPP_CPP11_STL_
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "runtime/json_reader.h"
#include "viewer/json_writer.h"
#include "viewer/serve_address.h"

namespace plumb::viewer {
namespace {

using WsClient = websocketpp::client<websocketpp::config::asio_client>;

// A client that subscribes to channel 1 when advertised and records what arrives.
struct TestClient {
  WsClient client;
  std::vector<std::string> texts;
  std::vector<std::string> binaries;
  std::atomic<bool> subscribed{false};
  std::thread thread;

  explicit TestClient(int port) {
    client.clear_access_channels(websocketpp::log::alevel::all);
    client.clear_error_channels(websocketpp::log::elevel::all);
    client.init_asio();
    client.set_message_handler([this](websocketpp::connection_hdl h, WsClient::message_ptr m) {
      if (m->get_opcode() == websocketpp::frame::opcode::text) {
        texts.push_back(m->get_payload());
        if (texts.back().find("\"advertise\"") != std::string::npos) {
          websocketpp::lib::error_code ec;
          client.send(h, R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":1}]})",
                      websocketpp::frame::opcode::text, ec);
          subscribed = true;
        }
      } else {
        binaries.push_back(m->get_payload());
      }
    });
    websocketpp::lib::error_code ec;
    WsClient::connection_ptr con = client.get_connection("ws://127.0.0.1:" + std::to_string(port) + "/", ec);
    con->add_subprotocol("foxglove.websocket.v1");
    client.connect(con);
  }
  void runFor(std::chrono::milliseconds d) {
    client.get_io_service().run_for(d);
  }
};

FoxgloveServerOptions loopback(std::size_t max_queued) {
  FoxgloveServerOptions o;
  o.port = 0;
  o.max_queued_bytes = max_queued;
  o.tick_hz = 100;
  return o;
}

std::vector<FoxgloveChannel> oneChannel() { return {{"/test", "test.Message", R"({"type":"object"})"}}; }

TEST(FoxgloveServer, OpensWithServerInfoAndAdvertiseAndSendsTheLatchedMessageOnSubscribe) {
  std::atomic<int> ticks{0};
  FoxgloveServer server(loopback(1 << 20), oneChannel(), {});
  ASSERT_TRUE(server.start([&] {
    if (ticks++ == 0) server.publish(0, 123, R"({"n":1})");
  }).ok());
  TestClient c(server.boundPort());
  c.runFor(std::chrono::milliseconds(1500));
  server.stop(0.5);
  ASSERT_GE(c.texts.size(), 2u);
  runtime::JsonValue info, advertise;
  ASSERT_TRUE(runtime::parseJson(c.texts[0], &info).ok());
  EXPECT_EQ(info.find("op")->string, "serverInfo");
  ASSERT_TRUE(runtime::parseJson(c.texts[1], &advertise).ok());
  EXPECT_EQ(advertise.find("op")->string, "advertise");
  const runtime::JsonValue& channel = advertise.find("channels")->items.at(0);
  EXPECT_EQ(channel.find("topic")->string, "/test");
  EXPECT_EQ(channel.find("schemaEncoding")->string, "jsonschema");
  ASSERT_EQ(c.binaries.size(), 1u);  // published before the subscription: latched
  const std::string& m = c.binaries[0];
  ASSERT_EQ(m.size(), 13u + 7u);
  EXPECT_EQ(uint8_t(m[0]), 1);  // Message Data
  EXPECT_EQ(uint8_t(m[1]), 7);  // subscription id, little-endian
  EXPECT_EQ(uint8_t(m[5]), 123);  // timestamp, little-endian
  EXPECT_EQ(m.substr(13), R"({"n":1})");
}

TEST(FoxgloveServer, AClientThatNeverReadsHasMessagesDroppedWhileThePublisherGoesOn) {
  std::atomic<bool> publish{false};
  std::atomic<int> published{0};
  std::atomic<int64_t> longest_tick_us{0};
  const std::string payload = "{\"x\":\"" + std::string(64 * 1024, 'a') + "\"}";
  FoxgloveServer server(loopback(256 * 1024), oneChannel(), {});
  ASSERT_TRUE(server.start([&] {
    if (!publish) return;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < 20; ++i, ++published) server.publish(0, 1, payload);
    const int64_t us = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - start).count();
    if (us > longest_tick_us) longest_tick_us = us;
  }).ok());
  TestClient c(server.boundPort());
  for (int i = 0; i < 100 && !c.subscribed; ++i) c.runFor(std::chrono::milliseconds(20));
  ASSERT_TRUE(c.subscribed);
  c.runFor(std::chrono::milliseconds(200));  // the subscription reaches the server
  publish = true;  // from here the client never reads again
  for (int i = 0; i < 200 && published < 2000; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  publish = false;
  server.stop(0);
  const FoxgloveServerStats s = server.stats();
  EXPECT_GE(published.load(), 2000);
  EXPECT_GT(s.messages_dropped, 0u);
  EXPECT_EQ(s.messages_dropped + s.messages_sent, uint64_t(published.load()) + 0u);
  // 20 publishes of 64 KB never waited for the client (generous: a loaded machine).
  EXPECT_LT(longest_tick_us.load(), 500000);
}

TEST(FoxgloveServer, RefusesClientsBeyondItsLimit) {
  FoxgloveServerOptions o = loopback(1 << 20);
  o.max_clients = 1;
  FoxgloveServer server(o, oneChannel(), {});
  ASSERT_TRUE(server.start([] {}).ok());
  TestClient first(server.boundPort());
  first.runFor(std::chrono::milliseconds(500));
  TestClient second(server.boundPort());
  second.runFor(std::chrono::milliseconds(500));
  server.stop(0);
  EXPECT_TRUE(first.subscribed);
  EXPECT_FALSE(second.subscribed);
  EXPECT_EQ(server.stats().clients_accepted, 1u);
  EXPECT_EQ(server.stats().clients_refused, 1u);
}

TEST(FoxgloveServer, RefusesAnAddressItCannotBind) {
  FoxgloveServerOptions o;
  o.host = "192.0.2.1";  // TEST-NET-1: no interface of this machine has it, nothing is sent
  o.port = 0;
  FoxgloveServer server(o, oneChannel(), {});
  const Status st = server.start([] {});
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("cannot listen on 192.0.2.1"), std::string::npos) << st.message();
}

TEST(ServeAddress, PortAloneIsLoopbackAndHostPortIsWhatTheUserNames) {
  ServeAddress a;
  ASSERT_TRUE(parseServeAddress("8765", &a).ok());
  EXPECT_EQ(a.host, "127.0.0.1");
  EXPECT_EQ(a.port, 8765);
  EXPECT_TRUE(a.loopback_only);
  ASSERT_TRUE(parseServeAddress("0.0.0.0:9000", &a).ok());
  EXPECT_EQ(a.host, "0.0.0.0");
  EXPECT_FALSE(a.loopback_only);
  ASSERT_TRUE(parseServeAddress("[::1]:8765", &a).ok());
  EXPECT_EQ(a.host, "::1");
  EXPECT_TRUE(a.loopback_only);
  ASSERT_TRUE(parseServeAddress("localhost:1", &a).ok());
  EXPECT_EQ(a.host, "127.0.0.1");
  for (const char* bad : {"", "x", "70000", "host:", ":80", "[::1]80", "1:2:3", "-1"}) {
    EXPECT_FALSE(parseServeAddress(bad, &a).ok()) << bad;
  }
}

TEST(JsonWriter, PlacesCommasAndKeepsDoublesExact) {
  JsonWriter w;
  w.beginObject().key("a").number(0.1).key("b").beginArray().number(1).string("x\"y").boolean(false).endArray();
  w.key("c").number(std::nan("")).endObject();
  runtime::JsonValue v;
  ASSERT_TRUE(runtime::parseJson(w.text(), &v).ok()) << w.text();
  EXPECT_EQ(v.find("a")->number, 0.1);
  EXPECT_EQ(v.find("b")->items.size(), 3u);
  EXPECT_EQ(v.find("b")->items[1].string, "x\"y");
  EXPECT_EQ(v.find("c")->type, runtime::JsonValue::Type::kNull);
}

}  // namespace
}  // namespace plumb::viewer
