#include "studio/studio_server.hpp"

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cstdio>
#include <deque>
#include <fmt/format.h>
#include <set>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "studio/design_limits.hpp"
#include "studio/path_safety.hpp"
#include "studio/wire_message.hpp"

namespace cleave::studio {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

constexpr std::uint32_t kMaxHeaderBytes = 8 * 1024;
constexpr std::uintmax_t kMaxServedFileBytes = 256u << 20;
constexpr auto kIdleHttpTimeout = std::chrono::seconds(30);

std::string mime_type(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".gltf") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  return "application/octet-stream";
}

bool downloadable_session_file(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  return ext == ".json" || ext == ".vtu" || ext == ".ply" || ext == ".gltf";
}

class WsClient;

}  // namespace

struct StudioServer::Impl {
  StudioSession& session;
  ServerOptions options;
  ServerHooks hooks;
  net::io_context io{1};
  tcp::acceptor acceptor{io};
  net::signal_set signals{io, SIGINT, SIGTERM};
  std::set<std::shared_ptr<WsClient>> clients;

  Impl(StudioSession& s, ServerOptions o, ServerHooks h) : session(s), options(std::move(o)), hooks(std::move(h)) {}
  void accept();
  /// To every client; `kind` says which unsent message it replaces (WsClient::send).
  void broadcast_now(const std::shared_ptr<const std::string>& text, BroadcastKind kind);
  nlohmann::json handle_text(const std::string& text, bool& design_changed);
};

namespace {

/// One WebSocket client: reads messages, answers through the handler, keeps a send queue.
class WsClient : public std::enable_shared_from_this<WsClient> {
 public:
  WsClient(tcp::socket&& socket, StudioServer::Impl& server) : ws_(std::move(socket)), server_(server) {}

  void start(http::request<http::string_body> request) {
    ws_.read_message_max(kMaxMessageBytes);
    // A message leaves as one frame: with Beast's default (fragments of 4 KiB, one write each) a
    // 45k-cell result went out as ~800 frames.
    ws_.auto_fragment(false);
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->server_.clients.insert(self);
      self->read();
    });
  }

  /// Queues `text`, or puts it in place of an unsent message it replaces (broadcast_kind.hpp).
  /// A broadcast state (the whole design after an edit) stays ahead of the sender's
  /// acknowledgement, which is queued after it; a client that reads slowly during a burst of
  /// edits from other clients holds one state, not one per edit.
  void send(std::shared_ptr<const std::string> text, BroadcastKind kind = BroadcastKind::every) {
    if (kind == BroadcastKind::every || kind == BroadcastKind::frame) enqueue(std::move(text), kind);
    else enqueue_replacing(std::move(text), kind);
  }

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        if (ec != websocket::error::closed && ec != net::error::eof && ec != net::error::operation_aborted &&
            ec != net::error::connection_reset)
          fmt::print(stderr, "cleave studio: a client's connection ended: {}\n", ec.message());
        self->close();
        return;
      }
      std::string text = beast::buffers_to_string(self->buffer_.data());
      self->buffer_.consume(self->buffer_.size());
      if (!self->ws_.got_text()) {
        self->send(std::make_shared<const std::string>(
            nlohmann::json{{"type", "error"}, {"message", "binary messages are not accepted; send JSON text"}}.dump()));
      } else {
        bool design_changed = false;
        nlohmann::json reply = self->server_.handle_text(text, design_changed);
        const bool is_hello = reply.value("type", "") == "state" && text.find("\"hello\"") != std::string::npos;
        // The new state reaches every client before the sender's acknowledgement, so a client
        // that acts on the ack already holds the state it acknowledges.
        if (design_changed)
          self->server_.broadcast_now(std::make_shared<const std::string>(self->server_.session.state_message().dump()),
                                      BroadcastKind::state);
        self->send(std::make_shared<const std::string>(reply.dump()));
        if (is_hello && self->server_.hooks.welcome_messages)
          for (std::string& m : self->server_.hooks.welcome_messages())
            self->send(std::make_shared<const std::string>(std::move(m)), BroadcastKind::full_result);
        if (design_changed && self->server_.hooks.design_changed) self->server_.hooks.design_changed(self->server_.session);
      }
      self->read();
    });
  }

  static bool is_result(BroadcastKind kind) { return kind == BroadcastKind::full_result || kind == BroadcastKind::partial_result; }

  /// Replaces the newest unsent message of `kind`'s family in place (a state any state; a full
  /// result any result queued after the last frame; a partial result only a partial one), else
  /// queues `text`.
  void enqueue_replacing(std::shared_ptr<const std::string> text, BroadcastKind kind) {
    if (closed_) return;
    for (std::size_t i = queue_.size(); i-- > 1;) {  // queue_[0] is being written
      Queued& queued = queue_[i];
      if (is_result(kind) && queued.kind == BroadcastKind::frame) break;
      const bool same_family = kind == BroadcastKind::state ? queued.kind == BroadcastKind::state : is_result(queued.kind);
      if (!same_family) continue;
      if (kind == BroadcastKind::partial_result && queued.kind != BroadcastKind::partial_result) break;
      queued_bytes_ = queued_bytes_ - queued.text->size() + text->size();
      queued.text = std::move(text);
      queued.kind = kind;
      return;
    }
    enqueue(std::move(text), kind);
  }

  void enqueue(std::shared_ptr<const std::string> text, BroadcastKind kind) {
    if (closed_) return;
    // A client that does not read: drop it before its queue holds everything since. One message
    // alone is never a backlog, whatever its size.
    if (queue_.size() >= kMaxQueuedMessages ||
        (!queue_.empty() && queued_bytes_ + text->size() > server_.options.max_queued_bytes)) {
      constexpr double kMiB = 1 << 20;
      fmt::print(stderr, "cleave studio: a client was disconnected: its send queue held {} messages, {:.2f} MiB (limits {}, {:.2f} MiB)\n",
                 queue_.size() + 1, static_cast<double>(queued_bytes_ + text->size()) / kMiB, kMaxQueuedMessages,
                 static_cast<double>(server_.options.max_queued_bytes) / kMiB);
      close();
      return;
    }
    queued_bytes_ += text->size();
    queue_.push_back({std::move(text), kind});
    if (queue_.size() == 1) write_next();
  }

  void write_next() {
    // The message being written is kept alive by the queue's front until its write completes.
    const std::string& text = *queue_.front().text;
    ws_.binary(is_binary_wire(text));
    ws_.async_write(net::buffer(text), [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec || self->closed_) {  // closed meanwhile (queue emptied): a write that still completed
        self->close();
        return;
      }
      self->queued_bytes_ -= self->queue_.front().text->size();
      self->queue_.pop_front();
      if (!self->queue_.empty()) self->write_next();
    });
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    queue_.clear();
    queued_bytes_ = 0;
    server_.clients.erase(shared_from_this());
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws_).socket().close(ignored);
  }

  websocket::stream<beast::tcp_stream> ws_;
  StudioServer::Impl& server_;
  beast::flat_buffer buffer_;
  struct Queued {
    std::shared_ptr<const std::string> text;
    BroadcastKind kind = BroadcastKind::every;  ///< what a newer message may replace it by while unsent
  };
  std::deque<Queued> queue_;
  std::size_t queued_bytes_ = 0;  ///< of the messages in queue_ (the one being written included)
  bool closed_ = false;
};

/// One HTTP connection: static files, session downloads, /api/state, or the upgrade to /ws.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(tcp::socket&& socket, StudioServer::Impl& server) : stream_(std::move(socket)), server_(server) {}

  void read() {
    parser_.emplace();
    parser_->header_limit(kMaxHeaderBytes);
    parser_->body_limit(kMaxHttpBodyBytes);
    stream_.expires_after(kIdleHttpTimeout);
    http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec == http::error::end_of_stream || ec == beast::error::timeout) return self->shutdown();
      if (ec == http::error::body_limit || ec == http::error::header_limit)
        return self->reply_text(http::status::payload_too_large, "request too large\n", false);
      if (ec) return self->reply_text(http::status::bad_request, "malformed request\n", false);
      self->handle(self->parser_->release());
    });
  }

 private:
  void handle(http::request<http::string_body> req) {
    const std::string target(req.target());
    if (websocket::is_upgrade(req)) {
      if (target != "/ws") return reply_text(http::status::not_found, "WebSocket endpoint is /ws\n", false);
      stream_.expires_never();
      std::make_shared<WsClient>(stream_.release_socket(), server_)->start(std::move(req));
      return;
    }
    keep_alive_ = req.keep_alive();
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return reply_text(http::status::method_not_allowed, "only GET is served\n", keep_alive_);
    head_only_ = req.method() == http::verb::head;
    std::string path = target.substr(0, target.find('?'));
    const auto decoded = percent_decode(path);
    if (!decoded) return reply_text(http::status::bad_request, "malformed URL escape\n", keep_alive_);
    path = *decoded;
    if (path == "/api/state") {
      return reply(http::status::ok, server_.session.state_message().dump(), "application/json", keep_alive_);
    }
    const std::filesystem::path& web = server_.options.web_root;
    std::optional<std::filesystem::path> file;
    if (path == "/" || path == "/index.html") file = resolve_inside(web, "index.html");
    else if (path == "/vendor/three.module.js") file = resolve_inside(web, "node_modules/three/build/three.module.js");
    else if (path == "/vendor/OrbitControls.js")
      file = resolve_inside(web, "node_modules/three/examples/jsm/controls/OrbitControls.js");
    else if (path.rfind("/session/", 0) == 0) {
      file = resolve_inside(server_.session.folder(), path.substr(9));
      if (file && !downloadable_session_file(*file)) file.reset();
    } else if (path.size() > 1 && path.rfind("/node_modules/", 0) != 0) {
      file = resolve_inside(web, path.substr(1));
    }
    if (!file) return reply_text(http::status::forbidden, "outside the served folders\n", keep_alive_);
    if (!std::filesystem::is_regular_file(*file)) {
      const bool vendor = path.rfind("/vendor/", 0) == 0;
      return reply_text(http::status::not_found,
                        vendor ? "three.js is missing: run scripts/install-web.sh\n" : "not found\n", keep_alive_);
    }
    std::string body;
    try {
      body = read_file(*file, kMaxServedFileBytes);
    } catch (const InputError&) {
      return reply_text(http::status::internal_server_error, "cannot read the file\n", keep_alive_);
    }
    reply(http::status::ok, std::move(body), mime_type(*file), keep_alive_);
  }

  void reply_text(http::status status, std::string text, bool keep_alive) {
    reply(status, std::move(text), "text/plain; charset=utf-8", keep_alive);
  }

  void reply(http::status status, std::string body, const std::string& type, bool keep_alive) {
    auto res = std::make_shared<http::response<http::string_body>>(status, 11);
    res->set(http::field::server, "cleave-studio");
    res->set(http::field::content_type, type);
    res->set(http::field::cache_control, "no-store");
    res->set("X-Content-Type-Options", "nosniff");
    res->keep_alive(keep_alive);
    const std::size_t size = body.size();
    if (!head_only_) res->body() = std::move(body);
    res->prepare_payload();
    if (head_only_) res->content_length(size);
    http::async_write(stream_, *res, [self = shared_from_this(), res, keep_alive](beast::error_code ec, std::size_t) {
      if (ec || !keep_alive) return self->shutdown();
      self->read();
    });
  }

  void shutdown() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  }

  beast::tcp_stream stream_;
  StudioServer::Impl& server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  bool keep_alive_ = false;
  bool head_only_ = false;
};

}  // namespace

void StudioServer::Impl::accept() {
  acceptor.async_accept(net::make_strand(io), [this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted) return;
    if (!ec) {
      // Replies go out at once: with Nagle's algorithm the last piece of a large result waited for
      // the client's delayed acknowledgement (40 ms on Linux) before it was sent.
      beast::error_code ignored;
      socket.set_option(tcp::no_delay(true), ignored);
      std::make_shared<HttpConnection>(std::move(socket), *this)->read();
    }
    accept();
  });
}

void StudioServer::Impl::broadcast_now(const std::shared_ptr<const std::string>& text, BroadcastKind kind) {
  const auto copy = clients;  // sending may drop a client from the set
  for (const auto& c : copy) c->send(text, kind);
}

nlohmann::json StudioServer::Impl::handle_text(const std::string& text, bool& design_changed) {
  if (hooks.extra_command && text.size() <= kMaxMessageBytes) {
    nlohmann::json message = nlohmann::json::parse(text, nullptr, false);
    if (message.is_object() && message.contains("cmd") && message["cmd"].is_string()) {
      try {
        if (auto reply = hooks.extra_command(message)) {
          if (message.contains("req")) (*reply)["req"] = message["req"];
          return *reply;
        }
      } catch (const InputError& e) {
        nlohmann::json r = {{"type", "error"}, {"message", e.what()}};
        if (message.contains("req")) r["req"] = message["req"];
        return r;
      }
    }
  }
  MessageOutcome out = handle_message(session, text, hooks.exporter);
  design_changed = out.design_changed;
  return std::move(out.reply);
}

StudioServer::StudioServer(StudioSession& session, ServerOptions options, ServerHooks hooks)
    : impl_(std::make_unique<Impl>(session, std::move(options), std::move(hooks))) {
  beast::error_code ec;
  const auto address = net::ip::make_address(impl_->options.bind_address, ec);
  if (ec) throw InputError(fmt::format("--host '{}': not an IP address", impl_->options.bind_address));
  const tcp::endpoint endpoint{address, impl_->options.port};
  impl_->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl_->acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) impl_->acceptor.bind(endpoint, ec);
  if (ec == net::error::address_in_use)
    throw InputError(fmt::format("port {} is already in use on {}; stop the other server or choose another --port",
                                 impl_->options.port, impl_->options.bind_address));
  if (ec == net::error::access_denied)
    throw InputError(fmt::format("port {} needs privileges on {}; choose a port above 1023 with --port",
                                 impl_->options.port, impl_->options.bind_address));
  if (!ec) impl_->acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec)
    throw InputError(fmt::format("cannot listen on {}:{}: {}", impl_->options.bind_address, impl_->options.port, ec.message()));
}

StudioServer::~StudioServer() = default;

std::uint16_t StudioServer::port() const { return impl_->acceptor.local_endpoint().port(); }

void StudioServer::run() {
  impl_->signals.async_wait([this](beast::error_code, int) { impl_->io.stop(); });
  impl_->accept();
  impl_->io.run();
}

void StudioServer::stop() {
  net::post(impl_->io, [this] { impl_->io.stop(); });
}

void StudioServer::broadcast(std::string text, BroadcastKind kind) {
  auto shared = std::make_shared<const std::string>(std::move(text));
  net::post(impl_->io, [this, shared, kind] { impl_->broadcast_now(shared, kind); });
}

}  // namespace cleave::studio
