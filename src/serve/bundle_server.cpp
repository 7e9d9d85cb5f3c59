#include "serve/bundle_server.hpp"

#include "base/text.hpp"

#include <httplib.h>
#include <sys/socket.h>

#include <array>
#include <cctype>
#include <atomic>
#include <chrono>
#include <fstream>
#include <map>
#include <mutex>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

namespace arwb::serve {

namespace {

// By extension (in any case), what a bundle holds; anything else is application/octet-stream. A browser refuses a
// module worker or WebAssembly streaming compilation under another type, and plays a video only under its own.
std::string content_type(std::string_view path) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 25> kTypes{{
      {".html", "text/html; charset=utf-8"}, {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"}, {".css", "text/css; charset=utf-8"},
      {".wasm", "application/wasm"}, {".json", "application/json"}, {".png", "image/png"},
      {".jpg", "image/jpeg"}, {".jpeg", "image/jpeg"}, {".gif", "image/gif"}, {".webp", "image/webp"},
      {".svg", "image/svg+xml"}, {".mp4", "video/mp4"}, {".m4v", "video/mp4"}, {".webm", "video/webm"},
      {".ogv", "video/ogg"}, {".pdf", "application/pdf"}, {".txt", "text/plain; charset=utf-8"},
      {".lua", "text/plain; charset=utf-8"}, {".xml", "application/xml"}, {".yml", "text/plain; charset=utf-8"},
      {".yaml", "text/plain; charset=utf-8"}, {".gltf", "model/gltf+json"}, {".glb", "model/gltf-binary"},
      {".woff2", "font/woff2"},
  }};
  std::string lower(path);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const auto& [ext, type] : kTypes)
    if (lower.size() > ext.size() && lower.ends_with(ext)) return std::string(type);
  return "application/octet-stream";
}

struct ServedFile {
  std::filesystem::path file;   // in the bundle's verified copy
  std::uint64_t size = 0;
  std::string type;
};

}  // namespace

struct BundleServer::Impl {
  bundle::OpenedBundle opened;
  std::map<std::string, ServedFile, std::less<>> files;   // by bundle path; "" is index.html
  httplib::Server server;
  std::thread thread;
  std::string url;
  int port = 0;
  std::atomic<std::uint64_t> requests{0};
  mutable std::mutex mutex;
  std::string last;

  explicit Impl(bundle::OpenedBundle o) : opened(std::move(o)) {}
  void answer(const httplib::Request& req, httplib::Response& res) const;
  void note(const httplib::Request& req, const httplib::Response& res, const ServeOptions& o);
};

// A listed file streamed from the verified copy in blocks (a video is never read whole), with Range requests
// answered by httplib (Safari plays a video only from a server that answers them). Cache-Control no-cache: the
// browser asks again each time, so a bundle exported anew is what it gets; offline, the page's service worker
// answers from its own verified copies.
void BundleServer::Impl::answer(const httplib::Request& req, httplib::Response& res) const {
  const std::string_view path = std::string_view(req.path).substr(1);
  const auto it = files.find(path.empty() ? std::string_view("index.html") : path);
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Content-Type-Options", "nosniff");
  if (it == files.end()) {
    res.status = 404;
    res.set_content(printable(path) + ": not in this bundle\n", "text/plain; charset=utf-8");
    return;
  }
  const ServedFile& f = it->second;
  if (f.size == 0) {   // httplib takes no content provider of length 0
    res.set_content("", f.type);
    return;
  }
  // httplib 0.11 neither checks ranges against the file's size nor trims them: a range that starts past the end is
  // answered 416 (RFC 9110, 15.5.17), and one that ends past it ends at the last byte, as RFC 9110, 14.1.2 says.
  const auto size = static_cast<ssize_t>(f.size);
  for (auto& [first, end] : const_cast<httplib::Ranges&>(req.ranges)) {
    if (first >= size || (first < 0 && end <= 0)) {
      res.status = 416;
      res.set_header("Content-Range", "bytes */" + std::to_string(f.size));
      return;
    }
    if (first >= 0 && end >= size) end = size - 1;   // `end` is the last byte's offset
    if (first < 0 && end > size) end = size;          // a suffix: `end` is its length
  }
  auto in = std::make_shared<std::ifstream>(f.file, std::ios::binary);
  res.set_content_provider(f.size, f.type, [in](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
    std::vector<char> block(std::min<std::size_t>(length, 256 * 1024));
    in->seekg(static_cast<std::streamoff>(offset));
    in->read(block.data(), static_cast<std::streamsize>(block.size()));
    const auto n = static_cast<std::size_t>(in->gcount());
    return n > 0 && sink.write(block.data(), n);
  });
}

void BundleServer::Impl::note(const httplib::Request& req, const httplib::Response& res, const ServeOptions& o) {
  // Appended, not added with +: GCC 12 warns of a false overlap in `req.method + " "` (-Wrestrict).
  std::string line = req.method;
  line.append(1, ' ').append(printable(req.path)).append(1, ' ').append(std::to_string(res.status));
  if (res.status == 200 || res.status == 206) {
    const auto it = files.find(req.path == "/" ? std::string_view("index.html") : std::string_view(req.path).substr(1));
    if (it != files.end()) line.append(1, ' ').append(human_bytes(it->second.size));
  }
  ++requests;
  {
    std::lock_guard lock(mutex);
    last = line;
  }
  if (o.log) o.log(line);
}

BundleServer::BundleServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

BundleServer::~BundleServer() { stop(); }
BundleServer::BundleServer(BundleServer&&) noexcept = default;
BundleServer& BundleServer::operator=(BundleServer&& o) noexcept {
  if (this != &o) {
    stop();
    impl_ = std::move(o.impl_);
  }
  return *this;
}

Result<BundleServer> BundleServer::start(const std::string& bundle_path, const ServeOptions& options) {
  Result<bundle::OpenedBundle> opened = bundle::open_bundle(bundle_path);
  if (!opened) return fail(opened.error());
  auto impl = std::make_unique<Impl>(std::move(*opened));
  const bundle::Manifest& m = impl->opened.manifest();
  const std::filesystem::path& dir = impl->opened.dir();
  bool page = false;
  for (const bundle::BundleFile& f : m.files) {
    impl->files.emplace(f.path, ServedFile{dir / f.path, f.size, content_type(f.path)});
    page = page || (f.role == "web" && f.path == "index.html");
  }
  if (!page) return fail(bundle_path + ": has no web page; export it again with --web");
  std::error_code ec;
  const auto manifest_size = std::filesystem::file_size(dir / bundle::kManifestName, ec);
  impl->files.emplace(bundle::kManifestName, ServedFile{dir / bundle::kManifestName, ec ? 0 : manifest_size,
                                                         content_type(bundle::kManifestName)});

  Impl* p = impl.get();
  // An idle browser connection holds one of httplib's threads, and stop() waits for it: 1 s, not httplib's 5, so
  // that Stop serving in the window answers at once.
  p->server.set_keep_alive_timeout(1);
  p->server.Get(R"(/.*)", [p](const httplib::Request& req, httplib::Response& res) { p->answer(req, res); });
  p->server.set_logger([p, options](const httplib::Request& req, const httplib::Response& res) {
    p->note(req, res, options);
  });
  // SO_REUSEADDR only: httplib's default also sets SO_REUSEPORT, with which a second server binds the same port
  // and the kernel splits the browser's connections between the two.
  p->server.set_socket_options([](socket_t sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  const std::string host = "127.0.0.1";
  if (options.port != 0 && p->server.bind_to_port(host, options.port)) p->port = options.port;
  else if (options.port == 0 || options.any_port_if_taken) p->port = p->server.bind_to_any_port(host);
  if (p->port <= 0) {
    return fail("cannot listen on " + host + ":" + std::to_string(options.port) +
                " (in use by another program, or below 1024 without root)");
  }
  p->url = "http://" + host + ":" + std::to_string(p->port) + "/";
  p->thread = std::thread([p] { p->server.listen_after_bind(); });
  // stop() only stops a server that is running: wait until it is, so that a stop right after start is not lost.
  while (!p->server.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return BundleServer(std::move(impl));
}

const std::string& BundleServer::url() const { return impl_->url; }
int BundleServer::port() const { return impl_->port; }
const bundle::Manifest& BundleServer::manifest() const { return impl_->opened.manifest(); }
std::uint64_t BundleServer::requests() const { return impl_->requests; }

std::string BundleServer::last_request() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->last;
}

void BundleServer::stop() {
  if (!impl_) return;   // moved from
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

void BundleServer::wait() {
  while (impl_->server.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

std::string phone_advice(int port) {
  const std::string p = std::to_string(port), url = "http://127.0.0.1:" + p + "/";
  return "On an Android phone over USB (USB debugging on): run `adb reverse tcp:" + p + " tcp:" + p +
         "`, then open " + url + " in Chrome on the phone, or scan the QR code.\n"
         "On any phone: put the bundle's files on a static HTTPS host and open its address.\n"
         "A phone gives the camera only to HTTPS or 127.0.0.1 pages: an http:// address on the local network "
         "shows the page's first screen saying so.\n";
}

}  // namespace arwb::serve
