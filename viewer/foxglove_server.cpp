#include "viewer/foxglove_server.h"

// websocketpp on standalone asio (no Boost), C++11 standard library primitives.
#define ASIO_STANDALONE
#define _WEBSOCKETPP_CPP11_STL_  // NOLINT(bugprone-reserved-identifier): websocketpp's own switch
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include <chrono>
#include <cstring>
#include <map>
#include <set>

#include "platform/allocation_counter.h"
#include "runtime/json_reader.h"
#include "runtime/thread_nice.h"
#include "viewer/json_writer.h"

namespace plumb::viewer {
namespace {

using WsServer = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;
namespace asio = websocketpp::lib::asio;

constexpr const char* kSubprotocol = "foxglove.websocket.v1";
constexpr uint8_t kOpMessageData = 1;

// The protocol's client operations this server does not offer (no capability advertised): a
// well-formed request gets an error status, the connection stays.
bool isUnsupportedProtocolOp(const std::string& op) {
  static const std::set<std::string> kOps = {
      "advertise",       "unadvertise", "getParameters", "setParameters", "subscribeParameterUpdates",
      "unsubscribeParameterUpdates", "subscribeConnectionGraph", "unsubscribeConnectionGraph", "fetchAsset"};
  return kOps.count(op) > 0;
}

// A JSON number that is an integer in [0, 2^32).
bool toUint32(const runtime::JsonValue* v, uint32_t* out) {
  if (v == nullptr || !v->isNumber()) return false;
  if (!(v->number >= 0 && v->number <= 4294967295.0) || v->number != double(uint64_t(v->number))) return false;
  *out = uint32_t(v->number);
  return true;
}

}  // namespace

struct FoxgloveServer::Impl {
  struct Client {
    std::map<uint32_t, std::size_t> channel_by_subscription;
    std::map<std::size_t, uint32_t> subscription_by_channel;
    uint64_t dropped = 0;
    bool awaiting_pong = false;
  };

  FoxgloveServerOptions options;
  std::vector<FoxgloveChannel> channels;
  std::vector<HttpAsset> assets;
  std::vector<std::string> latest;  // per channel: the last published binary frame's payload
  std::vector<uint64_t> latest_timestamp;
  std::vector<bool> has_latest;
  std::function<void()> tick;
  WsServer server;
  std::unique_ptr<asio::steady_timer> tick_timer, ping_timer, stop_timer;
  std::map<Handle, Client, std::owner_less<Handle>> clients;
  FoxgloveServerStats stats;
  std::string advertise_json, server_info_json;
  std::string frame;  // scratch: one Message Data frame
  std::chrono::steady_clock::time_point flush_deadline;
  bool stopping = false;

  void setUp();
  void scheduleTick();
  void schedulePing();
  void onOpen(Handle h);
  void onClose(Handle h);
  void onMessage(Handle h, WsServer::message_ptr message);
  void onHttp(Handle h);
  bool onValidate(Handle h);
  void closeMalformed(Handle h, const std::string& why);
  void sendText(Handle h, const std::string& text);
  void sendStatus(Handle h, int level, const std::string& message);
  bool sendMessage(Handle h, Client& client, uint32_t subscription, uint64_t timestamp_ns, std::string_view payload);
  void subscribe(Handle h, Client& client, const runtime::JsonValue& message);
  void unsubscribe(Handle h, Client& client, const runtime::JsonValue& message);
  void beginStop();
  void continueStop();
};

void FoxgloveServer::Impl::setUp() {
  server.clear_access_channels(websocketpp::log::alevel::all);
  server.clear_error_channels(websocketpp::log::elevel::all);
  server.init_asio();
  server.set_reuse_addr(true);
  server.set_max_message_size(options.max_client_message_bytes);
  server.set_max_http_body_size(options.max_client_message_bytes);
  server.set_validate_handler([this](Handle h) { return onValidate(h); });
  server.set_open_handler([this](Handle h) { onOpen(h); });
  server.set_close_handler([this](Handle h) { onClose(h); });
  server.set_fail_handler([this](Handle h) { onClose(h); });
  server.set_message_handler([this](Handle h, WsServer::message_ptr m) { onMessage(h, m); });
  server.set_http_handler([this](Handle h) { onHttp(h); });
  // Once the TCP connection exists (the socket is not open before accept): a fixed send buffer
  // (which also turns off the kernel's send-buffer autotuning, up to 4 MiB on loopback) and no
  // Nagle delay for the small pose messages.
  server.set_tcp_post_init_handler([this](Handle h) {
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = server.get_con_from_hdl(h, ec);
    if (ec || !con) return;
    asio::error_code aec;
    con->get_socket().set_option(asio::ip::tcp::no_delay(true), aec);
    if (options.socket_send_buffer_bytes > 0) {
      con->get_socket().set_option(asio::socket_base::send_buffer_size(options.socket_send_buffer_bytes), aec);
    }
  });
  server.set_pong_handler([this](Handle h, std::string) {
    auto it = clients.find(h);
    if (it != clients.end()) it->second.awaiting_pong = false;
  });

  JsonWriter info;
  info.beginObject();
  info.key("op").string("serverInfo");
  info.key("name").string(options.name);
  info.key("capabilities").beginArray().endArray();
  info.key("metadata").beginObject().key("readOnly").string("true").endObject();
  info.endObject();
  server_info_json = info.text();
  JsonWriter ad;
  ad.beginObject();
  ad.key("op").string("advertise");
  ad.key("channels").beginArray();
  for (std::size_t i = 0; i < channels.size(); ++i) {
    ad.beginObject();
    ad.key("id").number(uint64_t(i + 1));
    ad.key("topic").string(channels[i].topic);
    ad.key("encoding").string("json");
    ad.key("schemaName").string(channels[i].schema_name);
    ad.key("schema").string(channels[i].schema);
    ad.key("schemaEncoding").string("jsonschema");
    ad.endObject();
  }
  ad.endArray();
  ad.endObject();
  advertise_json = ad.text();
  latest.assign(channels.size(), std::string());
  latest_timestamp.assign(channels.size(), 0);
  has_latest.assign(channels.size(), false);
}

bool FoxgloveServer::Impl::onValidate(Handle h) {
  WsServer::connection_ptr con = server.get_con_from_hdl(h);
  if (clients.size() >= options.max_clients) {
    ++stats.clients_refused;
    con->set_status(websocketpp::http::status_code::service_unavailable);
    con->set_body("plumb's viewer already serves " + std::to_string(clients.size()) + " clients\n");
    return false;
  }
  for (const std::string& p : con->get_requested_subprotocols()) {
    if (p == kSubprotocol) {
      con->select_subprotocol(kSubprotocol);
      return true;
    }
  }
  ++stats.clients_refused;
  con->set_status(websocketpp::http::status_code::bad_request);
  con->set_body(std::string("plumb speaks the Foxglove WebSocket protocol: request subprotocol ") + kSubprotocol + "\n");
  return false;
}

void FoxgloveServer::Impl::onClose(Handle h) {
  // websocketpp itself closes a client whose message exceeds max_client_message_bytes (1009): a
  // client still in the table was not closed by us, so count it here.
  websocketpp::lib::error_code ec;
  WsServer::connection_ptr con = server.get_con_from_hdl(h, ec);
  if (clients.count(h) && !ec && con && con->get_local_close_code() == websocketpp::close::status::message_too_big) {
    ++stats.clients_closed_malformed;
  }
  clients.erase(h);
}

void FoxgloveServer::Impl::onOpen(Handle h) {
  if (stopping) {
    websocketpp::lib::error_code ec;
    server.close(h, websocketpp::close::status::going_away, "plumb is stopping", ec);
    return;
  }
  clients.emplace(h, Client{});
  ++stats.clients_accepted;
  stats.peak_clients = std::max<uint64_t>(stats.peak_clients, clients.size());
  sendText(h, server_info_json);
  sendText(h, advertise_json);
}

void FoxgloveServer::Impl::sendText(Handle h, const std::string& text) {
  websocketpp::lib::error_code ec;
  server.send(h, text, websocketpp::frame::opcode::text, ec);
}

void FoxgloveServer::Impl::sendStatus(Handle h, int level, const std::string& message) {
  JsonWriter w;
  w.beginObject();
  w.key("op").string("status");
  w.key("level").number(uint64_t(level));
  w.key("message").string(message);
  w.endObject();
  sendText(h, w.text());
}

void FoxgloveServer::Impl::closeMalformed(Handle h, const std::string& why) {
  ++stats.clients_closed_malformed;
  clients.erase(h);
  websocketpp::lib::error_code ec;
  // The reason travels in the close frame, whose payload is at most 123 bytes.
  server.close(h, websocketpp::close::status::policy_violation, why.substr(0, 120), ec);
}

void FoxgloveServer::Impl::onMessage(Handle h, WsServer::message_ptr message) {
  auto it = clients.find(h);
  if (it == clients.end()) return;
  if (message->get_opcode() != websocketpp::frame::opcode::text) {
    closeMalformed(h, "binary client messages are not accepted (no clientPublish capability)");
    return;
  }
  runtime::JsonValue json;
  const Status parsed = runtime::parseJson(message->get_payload(), &json);
  if (!parsed.ok()) {
    closeMalformed(h, "not JSON: " + parsed.message());
    return;
  }
  const runtime::JsonValue* op = json.find("op");
  if (json.type != runtime::JsonValue::Type::kObject || op == nullptr || !op->isString()) {
    closeMalformed(h, "a client message must be a JSON object with a string \"op\"");
    return;
  }
  if (op->string == "subscribe") {
    subscribe(h, it->second, json);
  } else if (op->string == "unsubscribe") {
    unsubscribe(h, it->second, json);
  } else if (isUnsupportedProtocolOp(op->string)) {
    sendStatus(h, 2, "plumb's viewer is read-only: \"" + op->string + "\" is not supported");
  } else {
    closeMalformed(h, "unknown op \"" + op->string.substr(0, 40) + "\"");
  }
}

void FoxgloveServer::Impl::subscribe(Handle h, Client& client, const runtime::JsonValue& message) {
  const runtime::JsonValue* list = message.find("subscriptions");
  if (list == nullptr || list->type != runtime::JsonValue::Type::kArray) {
    closeMalformed(h, "subscribe needs a \"subscriptions\" array");
    return;
  }
  // Checked whole before any takes effect: a malformed message changes nothing.
  for (const runtime::JsonValue& s : list->items) {
    uint32_t id = 0, channel_id = 0;
    if (!toUint32(s.find("id"), &id) || !toUint32(s.find("channelId"), &channel_id)) {
      closeMalformed(h, "each subscription needs integer \"id\" and \"channelId\"");
      return;
    }
  }
  for (const runtime::JsonValue& s : list->items) {
    uint32_t id = 0, channel_id = 0;
    toUint32(s.find("id"), &id);
    toUint32(s.find("channelId"), &channel_id);
    if (channel_id == 0 || channel_id > channels.size()) {
      sendStatus(h, 1, "no channel " + std::to_string(channel_id));
      continue;
    }
    const std::size_t channel = channel_id - 1;
    if (client.channel_by_subscription.count(id) || client.subscription_by_channel.count(channel)) {
      sendStatus(h, 1, "subscription " + std::to_string(id) + " or channel " + std::to_string(channel_id) +
                           " is already in use");
      continue;
    }
    client.channel_by_subscription[id] = channel;
    client.subscription_by_channel[channel] = id;
    if (has_latest[channel]) sendMessage(h, client, id, latest_timestamp[channel], latest[channel]);
  }
}

void FoxgloveServer::Impl::unsubscribe(Handle h, Client& client, const runtime::JsonValue& message) {
  const runtime::JsonValue* list = message.find("subscriptionIds");
  if (list == nullptr || list->type != runtime::JsonValue::Type::kArray) {
    closeMalformed(h, "unsubscribe needs a \"subscriptionIds\" array");
    return;
  }
  for (const runtime::JsonValue& v : list->items) {
    uint32_t id = 0;
    if (!toUint32(&v, &id)) {
      closeMalformed(h, "subscription ids are integers");
      return;
    }
  }
  for (const runtime::JsonValue& v : list->items) {
    uint32_t id = 0;
    toUint32(&v, &id);
    auto it = client.channel_by_subscription.find(id);
    if (it == client.channel_by_subscription.end()) continue;
    client.subscription_by_channel.erase(it->second);
    client.channel_by_subscription.erase(it);
  }
}

bool FoxgloveServer::Impl::sendMessage(Handle h, Client& client, uint32_t subscription, uint64_t timestamp_ns,
                                       std::string_view payload) {
  websocketpp::lib::error_code ec;
  WsServer::connection_ptr con = server.get_con_from_hdl(h, ec);
  if (ec || !con) return false;
  if (con->get_buffered_amount() + payload.size() > options.max_queued_bytes) {
    ++client.dropped;
    ++stats.messages_dropped;
    return false;
  }
  frame.resize(1 + 4 + 8);
  frame[0] = char(kOpMessageData);
  for (int i = 0; i < 4; ++i) frame[std::size_t(1 + i)] = char((subscription >> (8 * i)) & 0xff);
  for (int i = 0; i < 8; ++i) frame[std::size_t(5 + i)] = char((timestamp_ns >> (8 * i)) & 0xff);
  frame.append(payload.data(), payload.size());
  con->send(frame.data(), frame.size(), websocketpp::frame::opcode::binary);
  ++stats.messages_sent;
  return true;
}

void FoxgloveServer::Impl::onHttp(Handle h) {
  WsServer::connection_ptr con = server.get_con_from_hdl(h);
  ++stats.http_requests;
  std::string resource = con->get_resource();
  const std::size_t query = resource.find('?');
  if (query != std::string::npos) resource.resize(query);
  if (resource == "/") resource = "/index.html";
  if (con->get_request().get_method() != "GET") {
    con->set_status(websocketpp::http::status_code::method_not_allowed);
    return;
  }
  for (const HttpAsset& a : assets) {
    if (resource != a.path) continue;
    con->set_status(websocketpp::http::status_code::ok);
    con->replace_header("Content-Type", a.content_type);
    con->replace_header("Cache-Control", "no-cache");
    con->set_body(std::string(reinterpret_cast<const char*>(a.data), a.size));
    return;
  }
  con->set_status(websocketpp::http::status_code::not_found);
  con->replace_header("Content-Type", "text/plain; charset=utf-8");
  con->set_body(assets.empty() ? "this plumb was built without its viewer page (docs/VIEWER.md); "
                                 "connect Foxglove or Lichtblick to this address instead\n"
                               : "not found\n");
}

void FoxgloveServer::Impl::scheduleTick() {
  tick_timer->expires_after(std::chrono::microseconds(1000000 / std::max(1, options.tick_hz)));
  tick_timer->async_wait([this](const asio::error_code& ec) {
    if (ec || stopping) return;
    tick();
    scheduleTick();
  });
}

void FoxgloveServer::Impl::schedulePing() {
  ping_timer->expires_after(std::chrono::milliseconds(options.ping_interval_ms));
  ping_timer->async_wait([this](const asio::error_code& ec) {
    if (ec || stopping) return;
    std::vector<Handle> silent;
    for (auto& [h, client] : clients) {
      if (client.awaiting_pong) {
        silent.push_back(h);
        continue;
      }
      client.awaiting_pong = true;
      websocketpp::lib::error_code e;
      server.ping(h, "", e);
    }
    for (const Handle& h : silent) {
      ++stats.clients_timed_out;
      clients.erase(h);
      websocketpp::lib::error_code e;
      server.close(h, websocketpp::close::status::policy_violation, "no answer to ping", e);
    }
    schedulePing();
  });
}

void FoxgloveServer::Impl::beginStop() {
  tick();  // the last state of the run reaches the clients
  stopping = true;
  tick_timer->cancel();
  ping_timer->cancel();
  websocketpp::lib::error_code ec;
  server.stop_listening(ec);
  continueStop();
}

// Every 20 ms until the queues drained or the deadline passed; then every client is closed and
// the loop ends once they are gone (or half a second later).
void FoxgloveServer::Impl::continueStop() {
  bool drained = true;
  for (auto& [h, client] : clients) {
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = server.get_con_from_hdl(h, ec);
    if (!ec && con && con->get_buffered_amount() > 0) drained = false;
  }
  const auto now = std::chrono::steady_clock::now();
  if (drained || now >= flush_deadline) {
    for (auto& [h, client] : clients) {
      websocketpp::lib::error_code ec;
      server.close(h, websocketpp::close::status::going_away, "the run ended", ec);
    }
    clients.clear();
    stop_timer->expires_after(std::chrono::milliseconds(500));
    stop_timer->async_wait([this](const asio::error_code&) { server.stop(); });
    return;
  }
  stop_timer->expires_after(std::chrono::milliseconds(20));
  stop_timer->async_wait([this](const asio::error_code& ec) {
    if (!ec) continueStop();
  });
}

FoxgloveServer::FoxgloveServer(FoxgloveServerOptions options, std::vector<FoxgloveChannel> channels,
                               std::vector<HttpAsset> assets)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->channels = std::move(channels);
  impl_->assets = std::move(assets);
}

FoxgloveServer::~FoxgloveServer() { stop(0); }

Status FoxgloveServer::start(std::function<void()> tick) {
  Impl& m = *impl_;
  m.tick = std::move(tick);
  m.setUp();
  asio::error_code aec;
  const asio::ip::address address = asio::ip::make_address(m.options.host, aec);
  if (aec) return Status::Error("--serve: '" + m.options.host + "' is not an IP address");
  if (m.options.port < 0 || m.options.port > 65535) return Status::Error("--serve: port must be within 0..65535");
  websocketpp::lib::error_code ec;
  m.server.listen(asio::ip::tcp::endpoint(address, uint16_t(m.options.port)), ec);
  if (ec) {
    return Status::Error("--serve: cannot listen on " + m.options.host + ":" + std::to_string(m.options.port) + ": " +
                         ec.message());
  }
  m.server.start_accept(ec);
  if (ec) return Status::Error("--serve: cannot accept connections: " + ec.message());
  const asio::ip::tcp::endpoint local = m.server.get_local_endpoint(aec);
  bound_port_ = aec ? m.options.port : int(local.port());
  m.tick_timer = std::make_unique<asio::steady_timer>(m.server.get_io_service());
  m.ping_timer = std::make_unique<asio::steady_timer>(m.server.get_io_service());
  m.stop_timer = std::make_unique<asio::steady_timer>(m.server.get_io_service());
  m.scheduleTick();
  m.schedulePing();
  const int nice_value = m.options.thread_nice;
  thread_ = std::thread([this, nice_value] {
    excludeThisThreadFromAllocationCount();
    if (nice_value > 0) (void)runtime::setCurrentThreadNice(nice_value);
    impl_->server.run();
  });
  running_ = true;
  return Status::Ok();
}

void FoxgloveServer::stop(double flush_seconds) {
  if (!running_) return;
  running_ = false;
  Impl& m = *impl_;
  m.flush_deadline = std::chrono::steady_clock::now() +
                     std::chrono::milliseconds(int64_t(std::max(0.0, flush_seconds) * 1000));
  asio::post(m.server.get_io_service(), [&m] { m.beginStop(); });
  thread_.join();
}

void FoxgloveServer::publish(std::size_t channel, uint64_t timestamp_ns, std::string_view json) {
  Impl& m = *impl_;
  if (channel >= m.channels.size()) return;
  m.latest[channel].assign(json.data(), json.size());
  m.latest_timestamp[channel] = timestamp_ns;
  m.has_latest[channel] = true;
  for (auto& [h, client] : m.clients) {
    auto it = client.subscription_by_channel.find(channel);
    if (it != client.subscription_by_channel.end()) m.sendMessage(h, client, it->second, timestamp_ns, json);
  }
}

bool FoxgloveServer::hasSubscribers(std::size_t channel) const {
  for (const auto& [h, client] : impl_->clients) {
    if (client.subscription_by_channel.count(channel)) return true;
  }
  return false;
}

std::size_t FoxgloveServer::clientCount() const { return impl_->clients.size(); }

FoxgloveServerStats FoxgloveServer::stats() const { return impl_->stats; }

}  // namespace plumb::viewer
