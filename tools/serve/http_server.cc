#include "tools/serve/http_server.h"

#include <httplib.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>

#include <Eigen/Geometry>
#include <atomic>
#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "serve_viewer_assets.h"
#include "tools/serve/request_error.h"

namespace litgs::serve {
namespace {

using nlohmann::json;

void send_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& message) {
  send_json(res, status, {{"error", message}, {"status", status}});
  if (status == 503) res.set_header("Retry-After", "1");
}

std::string endpoint_label(const std::string& path) {
  static const char* known[] = {"/",      "/viewer.js", "/palettes",    "/healthz", "/metrics",
                                "/model", "/models",    "/models/load", "/render"};
  for (const char* k : known)
    if (path == k) return path;
  return path.rfind("/scene/frames/", 0) == 0 ? "/scene/frames" : "other";
}

// Every handler runs inside this: RequestError becomes its status with a JSON error, anything else a 500
// (the server's fault, never the client's); the answer is counted before it is sent, so /metrics is
// up to date for the next request.
template <class Handler>
httplib::Server::Handler guarded(Metrics& metrics, Handler handler) {
  return [&metrics, handler](const httplib::Request& req, httplib::Response& res) {
    const auto start = std::chrono::steady_clock::now();
    try {
      handler(req, res);
      if (res.status == -1) res.status = 200;  // httplib's "not set"
    } catch (const RequestError& e) {
      send_error(res, e.status, e.what());
    } catch (const std::exception& e) {
      send_error(res, 500, std::string("internal error: ") + e.what());
    }
    metrics.count_request(endpoint_label(req.path), res.status,
                          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  };
}

void require_json(const httplib::Request& req) {
  const std::string type = req.get_header_value("Content-Type");
  if (type.rfind("application/json", 0) != 0)
    throw RequestError(415, "Content-Type must be application/json, not '" + type + "'");
}

std::vector<std::pair<std::string, std::string>> query(const httplib::Request& req) {
  return {req.params.begin(), req.params.end()};
}

void refuse_query(const httplib::Request& req, const std::vector<std::string>& allowed) {
  for (const auto& [name, value] : req.params)
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end())
      throw RequestError(400, "unknown query parameter '" + name + "' for " + req.path);
}

// The methods each known path takes (405 for the others).
constexpr std::pair<const char*, const char*> kMethods[] = {
    {"/", "GET"},        {"/viewer.js", "GET"},    {"/palettes", "GET"},
    {"/healthz", "GET"}, {"/metrics", "GET"},      {"/model", "GET"},
    {"/models", "GET"},  {"/models/load", "POST"}, {"/render", "GET, POST"}};

const char* allowed_methods(const std::string& path) {
  for (const auto& [p, allowed] : kMethods)
    if (path == p) return allowed;
  return nullptr;
}

void refuse_method(const httplib::Request& req, httplib::Response& res, const std::string& allowed) {
  send_error(res, 405, req.method + " is not allowed on " + req.path + " (allowed: " + allowed + ")");
  res.set_header("Allow", allowed);
}

json array3(const std::array<double, 3>& a) {
  return json::array({a[0], a[1], a[2]});
}

json units_json(const std::optional<ImageUnits>& u) {
  if (!u) return {{"name", "model units"}, {"low", 0.0}, {"high", 1.0}, {"source", nullptr}};
  return {{"name", u->name}, {"low", u->low}, {"high", u->high}, {"source", u->source}};
}

json summary_json(const ModelSummary& s) {
  return {{"name", s.name},
          {"version", s.version},
          {"path", s.path},
          {"gaussians", s.gaussians},
          {"channels", s.channels},
          {"sh_degree", s.sh_degree},
          {"bounds", {{"min", array3(s.bounds_min)}, {"max", array3(s.bounds_max)}}},
          {"pose_frame", s.frame},
          {"frame_offset_m", array3(s.frame_offset)},
          {"device_bytes", s.device_bytes},
          {"image_units", units_json(s.image_units)}};
}

json camera_json(const SceneCamera& c) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) R(r, k) = c.camera.R_cam_world[k][r];  // glm is column-major
  const Eigen::Quaterniond q = Eigen::Quaterniond(R).normalized();
  const auto& K = c.camera;
  return {{"index", c.index},
          {"t_s", c.t_s},
          {"image", c.image},
          {"frame_url", "/scene/frames/" + std::to_string(c.index) + ".png"},
          {"width", K.width},
          {"height", K.height},
          {"intrinsics", {{"fx", K.fx}, {"fy", K.fy}, {"cx", K.cx}, {"cy", K.cy}}},
          {"pose",
           {{"T_cam_world",
             {{"q", {q.w(), q.x(), q.y(), q.z()}},
              {"t", {K.t_cam_world.x, K.t_cam_world.y, K.t_cam_world.z}}}}}}};
}

void add_routes(httplib::Server& svr, Service& service) {
  Metrics& metrics = service.metrics();
  const auto asset = [&metrics](const unsigned char* data, size_t size, const char* type) {
    return guarded(metrics, [data, size, type](const httplib::Request&, httplib::Response& res) {
      res.set_content(reinterpret_cast<const char*>(data), size, type);
    });
  };
  svr.Get("/", asset(litgs_viewer_index_html, sizeof litgs_viewer_index_html, "text/html; charset=utf-8"));
  svr.Get("/viewer.js", asset(litgs_viewer_js, sizeof litgs_viewer_js, "text/javascript; charset=utf-8"));
  svr.Get("/palettes", guarded(metrics, [](const httplib::Request& req, httplib::Response& res) {
            refuse_query(req, {});
            json j = json::object();
            for (const std::string& name : io::palette_names()) {
              json colours = json::array();
              for (const io::Rgb& c : io::palette_table(io::parse_palette(name)))
                colours.push_back({c[0], c[1], c[2]});
              j[name] = colours;
            }
            send_json(res, 200, j);
          }));
  svr.Get("/healthz", guarded(metrics, [&service](const httplib::Request& req, httplib::Response& res) {
            refuse_query(req, {});
            json j = {{"status", "ok"},
                      {"models", service.models().summaries().size()},
                      {"queue", service.queue_depth()}};
            if (const auto errors = service.validation_errors()) j["validation_errors"] = *errors;
            send_json(res, 200, j);
          }));
  svr.Get("/metrics", guarded(metrics, [&service](const httplib::Request& req, httplib::Response& res) {
            refuse_query(req, {});
            std::string gauges =
                "# HELP litgs_queue_depth Device jobs waiting.\n# TYPE litgs_queue_depth gauge\n";
            gauges += "litgs_queue_depth " + std::to_string(service.queue_depth()) + "\n";
            gauges +=
                "# HELP litgs_renders_in_flight Render requests not yet answered.\n# TYPE "
                "litgs_renders_in_flight gauge\nlitgs_renders_in_flight " +
                std::to_string(service.renders_in_flight()) + "\n";
            gauges +=
                "# HELP litgs_model_gaussians Gaussians of each loaded model.\n# TYPE litgs_model_gaussians "
                "gauge\n";
            std::string bytes =
                "# HELP litgs_model_device_bytes Device memory of each model.\n# TYPE "
                "litgs_model_device_bytes gauge\n";
            for (const ModelSummary& m : service.models().summaries()) {
              gauges +=
                  "litgs_model_gaussians{model=\"" + m.name + "\"} " + std::to_string(m.gaussians) + "\n";
              bytes += "litgs_model_device_bytes{model=\"" + m.name + "\"} " +
                       std::to_string(m.device_bytes) + "\n";
            }
            res.set_content(service.metrics().text(gauges + bytes), "text/plain; version=0.0.4");
          }));
  svr.Get("/model", guarded(metrics, [&service](const httplib::Request& req, httplib::Response& res) {
            refuse_query(req, {"name"});
            const std::string name = req.has_param("name") ? req.get_param_value("name") : "default";
            const std::optional<ModelSummary> s = service.models().summary(name);
            if (!s) throw RequestError(404, "unknown model '" + name + "'");
            json j = summary_json(*s);
            j["max_pixels"] = service.options().max_pixels;
            j["device"] = service.device().name;
            json cameras = json::array();
            for (const SceneCamera& c : service.scene_cameras()) cameras.push_back(camera_json(c));
            j["scene"] = service.options().scene.empty()
                             ? json(nullptr)
                             : json{{"dir", service.options().scene}, {"cameras", cameras}};
            send_json(res, 200, j);
          }));
  svr.Get("/models", guarded(metrics, [&service](const httplib::Request& req, httplib::Response& res) {
            refuse_query(req, {});
            json list = json::array();
            for (const ModelSummary& m : service.models().summaries()) list.push_back(summary_json(m));
            send_json(res, 200, {{"models", list}});
          }));
  svr.Post("/models/load", guarded(metrics, [&service](const httplib::Request& req, httplib::Response& res) {
             require_json(req);
             json j;
             try {
               j = json::parse(req.body);
             } catch (const json::exception& e) {
               throw RequestError(400, std::string("malformed JSON: ") + e.what());
             }
             if (!j.is_object())
               throw RequestError(400, "the request body must be a JSON object {name, path}");
             for (const auto& item : j.items())
               if (item.key() != "name" && item.key() != "path")
                 throw RequestError(400, "unknown field '" + item.key() + "' (allowed here: name, path)");
             if (!j.contains("name") || !j["name"].is_string())
               throw RequestError(400, "missing string field 'name'");
             if (!j.contains("path") || !j["path"].is_string())
               throw RequestError(400, "missing string field 'path'");
             const std::string name = j["name"];
             static const std::regex kName("[A-Za-z0-9_.-]{1,64}");
             if (!std::regex_match(name, kName))
               throw RequestError(400, "field 'name' must be 1-64 characters of A-Z a-z 0-9 _ . -");
             const std::filesystem::path path =
                 confine_to_models_dir(service.options().models_dir, j["path"]);
             ModelSummary s;
             try {
               s = service.load(name, path);
             } catch (const RequestError&) {
               throw;
             } catch (const std::exception& e) {
               throw RequestError(400, "cannot load '" + j["path"].get<std::string>() + "': " + e.what());
             }
             send_json(res, 200, summary_json(s));
           }));
  const auto render = [&service](const RenderRequest& request, httplib::Response& res) {
    const auto start = std::chrono::steady_clock::now();
    ModelSummary used;
    const RenderedView view = service.render(request, &used);
    EncodedBody body = encode_outputs(request, view);
    for (const auto& [k, v] : body.headers) res.set_header(k, v);
    res.set_header("X-Model-Version", used.name + "@" + std::to_string(used.version));
    res.set_header("X-Device-Ms", std::to_string(view.device_seconds * 1e3));
    res.set_header(
        "X-Render-Ms",
        std::to_string(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count()));
    res.set_content(std::move(body.body), body.content_type);
  };
  const RequestLimits limits{service.options().max_pixels};
  svr.Post("/render", guarded(metrics, [render, limits](const httplib::Request& req, httplib::Response& res) {
             require_json(req);
             render(parse_render_json(req.body, limits), res);
           }));
  svr.Get("/render", guarded(metrics, [render, limits](const httplib::Request& req, httplib::Response& res) {
            render(parse_render_query(query(req), limits), res);
          }));
  svr.Get(R"(/scene/frames/(\d{1,9})\.png)",
          guarded(metrics, [&service](const httplib::Request& req, httplib::Response& res) {
            refuse_query(req, {});
            const std::vector<uint8_t> png = service.scene_frame_png(std::stoul(req.matches[1].str()));
            res.set_content(reinterpret_cast<const char*>(png.data()), png.size(), "image/png");
          }));

  // Known paths with a method they do not take: 405 naming the one they do.
  for (const auto& [path, allowed] : kMethods) {
    const auto refuse = guarded(
        metrics, [allowed = std::string(allowed)](const httplib::Request& req, httplib::Response& res) {
          refuse_method(req, res, allowed);
        });
    if (std::string(allowed).find("POST") == std::string::npos) svr.Post(path, refuse);
    if (std::string(allowed).find("GET") == std::string::npos) svr.Get(path, refuse);
    svr.Put(path, refuse);
    svr.Delete(path, refuse);
    svr.Patch(path, refuse);
  }
}

void configure(httplib::Server& svr, Service& service) {
  const ServeOptions& o = service.options();
  const size_t threads = o.threads ? o.threads : o.max_queue + 4;
  svr.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  svr.set_payload_max_length(o.max_body_bytes);
  svr.set_read_timeout(o.read_timeout_s, 0);
  svr.set_write_timeout(o.read_timeout_s, 0);
  svr.set_keep_alive_timeout(o.read_timeout_s);
  // httplib's own refusals (unknown path, oversized body, malformed request line) get a JSON error too.
  svr.set_error_handler(httplib::Server::HandlerWithResponse(
      [max_body = o.max_body_bytes, &service](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;  // ours: counted already
        // httplib refuses a body-less PUT/PATCH with 400 before any handler runs: the method is the mistake.
        const char* allowed = allowed_methods(req.path);
        if (res.status == 400 && allowed && !req.method.empty() &&
            std::string(allowed).find(req.method) == std::string::npos) {
          refuse_method(req, res, allowed);
          service.metrics().count_request(endpoint_label(req.path), res.status, 0.0);
          return httplib::Server::HandlerResponse::Handled;
        }
        service.metrics().count_request(endpoint_label(req.path), res.status, 0.0);
        std::string message = "error " + std::to_string(res.status);
        if (res.status == 404) message = "no such endpoint: " + req.method + " " + req.path;
        if (res.status == 413)
          message = "request body larger than --max-body " + std::to_string(max_body) + " bytes";
        if (res.status == 400) message = "malformed HTTP request";
        if (res.status == 414) message = "request line too long";
        send_error(res, res.status, message);
        return httplib::Server::HandlerResponse::Handled;
      }));
}

}  // namespace

int run_http_server(const ServeOptions& options) {
  // SIGINT/SIGTERM are taken by one thread (sigwait) that stops the server; every other thread, the device
  // thread and httplib's included, inherits the blocked mask.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  sigset_t previous;
  pthread_sigmask(SIG_BLOCK, &stop_signals, &previous);
  ::signal(SIGPIPE, SIG_IGN);

  Service service(options);
  httplib::Server svr;
  configure(svr, service);
  add_routes(svr, service);

  // httplib listens with a backlog of 5 (compiled into Debian's library): many clients connecting at once
  // would overflow it and their connections be dropped. Keep the listening socket and listen again on it
  // with the system's maximum (Linux updates the backlog of a listening socket).
  int listen_fd = -1;
  svr.set_socket_options([&listen_fd](socket_t sock) {
    const int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    listen_fd = sock;
  });
  int port = options.port;
  if (port == 0) {
    port = svr.bind_to_any_port(options.host);
  } else if (!svr.bind_to_port(options.host, port)) {
    port = -1;
  }
  if (port < 0)
    throw std::runtime_error("cannot listen on " + options.host + ":" + std::to_string(options.port));
  if (listen_fd >= 0) ::listen(listen_fd, SOMAXCONN);

  std::atomic<bool> signalled{false};
  std::thread waiter([&] {
    int sig = 0;
    sigwait(&stop_signals, &sig);
    signalled = true;
    svr.stop();
  });
  const ModelSummary model = *service.models().summary("default");
  std::cout << "serve: " << model.gaussians << " Gaussians (" << model.path << ") on "
            << service.device().name << "\nserve: listening on http://" << options.host << ":" << port
            << std::endl;
  const bool ok = svr.listen_after_bind();
  if (!signalled) pthread_kill(waiter.native_handle(), SIGTERM);  // wake the waiter
  waiter.join();
  service.stop();
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  std::cout << "serve: stopped" << (signalled ? " (signal)" : "") << std::endl;
  if (!ok && !signalled) throw std::runtime_error("the HTTP server stopped unexpectedly");
  return 0;
}

}  // namespace litgs::serve
