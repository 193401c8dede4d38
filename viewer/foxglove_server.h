#pragma once
// FoxgloveServer: a read-only Foxglove WebSocket protocol v1 server (subprotocol
// `foxglove.websocket.v1`, docs/VIEWER.md) with JSON-encoded channels, plus plain HTTP GET for
// plumb's own page on the same port. It knows nothing of odometry: a producer registers channels
// and publishes JSON payloads from the tick callback; the server fans them out.
//
// WebSocket framing, the HTTP handshake and HTTP requests are websocketpp's (Debian
// libwebsocketpp-dev, on standalone asio from libasio-dev: what Foxglove's own C++ server uses),
// never ours. Everything runs on ONE thread of its own (start() to stop()): the handlers and the
// tick, so nothing here takes a lock. That thread is excluded from the frame path's allocation
// count (platform/allocation_counter.h) and niced: it serves whatever CPU the run leaves.
//
// Per client: a client that reads slowly (or never) gets messages dropped once its send queue
// holds max_queued_bytes (counted per client and in Stats); a client that stops answering pings
// is closed. A malformed client message (not a JSON object with a known `op`, bad fields, a
// binary message: no clientPublish capability) or one larger than max_client_message_bytes
// closes that client (close codes 1008 / 1009), nothing else. No client message reaches the
// producer: subscriptions only pick what that client is sent.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "platform/status.h"

namespace plumb::viewer {

// A file the server sends for an HTTP GET of `path` (the page, viewer/page_assets.h).
struct HttpAsset {
  const char* path;
  const char* content_type;
  const unsigned char* data;
  std::size_t size;
};

struct FoxgloveServerOptions {
  std::string host = "127.0.0.1";  // the address to bind (loopback unless the user names another)
  int port = 8765;                 // 0: any free port (boundPort() tells which)
  std::string name = "plumb";      // serverInfo.name
  int tick_hz = 30;                // how often the tick callback runs
  std::size_t max_client_message_bytes = 64 * 1024;  // larger: close code 1009
  // Per client, beyond what the kernel's socket buffer holds: more and its messages are dropped
  // (a viewer that far behind is seconds late; newer messages replace what it missed).
  std::size_t max_queued_bytes = 1024 * 1024;
  // The kernel's send buffer per client (SO_SNDBUF; Linux doubles it). Small on purpose: what a
  // slow client has not taken waits in the queue above, where it is bounded and counted, not in
  // megabytes of kernel buffer that arrive seconds late. 64 KiB still moves ~6 MB/s at 20 ms RTT.
  int socket_send_buffer_bytes = 64 * 1024;
  int ping_interval_ms = 5000;  // a client that does not answer a ping within this is closed
  std::size_t max_clients = 64;  // more are refused at the handshake (HTTP 503): bounded memory
  int thread_nice = 10;         // the server thread's nice value (0: unchanged)
};

struct FoxgloveChannel {
  std::string topic;
  std::string schema_name;  // e.g. "foxglove.PoseInFrame"
  std::string schema;       // JSON Schema text (encoding "json", schemaEncoding "jsonschema")
};

struct FoxgloveServerStats {
  uint64_t clients_accepted = 0;
  uint64_t clients_refused = 0;           // no foxglove.websocket.v1 subprotocol, or max_clients reached
  uint64_t clients_closed_malformed = 0;  // malformed or oversized client messages
  uint64_t clients_timed_out = 0;         // did not answer a ping
  uint64_t messages_sent = 0;
  uint64_t messages_dropped = 0;          // not sent: that client's queue was full
  uint64_t http_requests = 0;
  uint64_t peak_clients = 0;
};

class FoxgloveServer {
 public:
  // assets: served at their paths for HTTP GET (may be empty: then every GET is 404).
  FoxgloveServer(FoxgloveServerOptions options, std::vector<FoxgloveChannel> channels, std::vector<HttpAsset> assets);
  ~FoxgloveServer();  // stop(0) when still running
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  // Binds (an error names the address: in use, not local, ...) and starts the thread; `tick`
  // then runs on it tick_hz times a second, and once more at stop().
  Status start(std::function<void()> tick);
  // Runs the final tick, waits up to flush_seconds for the clients' queues to drain, closes every
  // client (1001 going away) and joins the thread. Idempotent.
  void stop(double flush_seconds);
  int boundPort() const { return bound_port_; }

  // Server thread only (from the tick). Sends `json` to every subscriber of `channel` (an index
  // into the constructor's list) as Message Data (opcode 1) stamped timestamp_ns, and keeps it
  // as the channel's latest message, which a later subscriber gets at once.
  void publish(std::size_t channel, uint64_t timestamp_ns, std::string_view json);
  bool hasSubscribers(std::size_t channel) const;
  std::size_t clientCount() const;

  // Read after stop() (or approximately while running).
  FoxgloveServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::thread thread_;
  int bound_port_ = 0;
  bool running_ = false;
};

}  // namespace plumb::viewer
