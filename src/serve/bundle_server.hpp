// A bundle's phone page served over HTTP on this computer: `arwb serve` and File > Export...'s Serve. The bundle is
// opened as the player opens it (bundle::open_bundle: copied into a private folder and verified against its
// manifest), and only the files its manifest lists, and manifest.json, are served from that copy: what a browser
// gets is what was verified, even if the original changes meanwhile. docs/export.md, "On a phone".
#pragma once

#include "base/result.hpp"
#include "bundle/bundle.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace arwb::serve {

struct ServeOptions {
  int port = 8000;                    // on 127.0.0.1; 0: any free port
  bool any_port_if_taken = false;     // `port` is taken: listen on any free one rather than fail
  // One line per request answered ("GET /web/arwb_core.wasm 200 1.4 MiB"), called from the server's threads;
  // may be null.
  std::function<void(const std::string&)> log;
};

// Listens on 127.0.0.1 only: a phone's browser gives the camera to a secure page, HTTPS or 127.0.0.1, so the ways to
// a phone are `adb reverse` (USB) or an HTTPS host (phone_advice), never this server on the local network.
class BundleServer {
 public:
  // Refused, in one line: a bundle open_bundle refuses ("museum.arwb: scene/x.lua: not in the manifest"), one
  // without the phone page ("museum.arwb: has no web page; export it again with --web"), a port that cannot be
  // listened on ("cannot listen on 127.0.0.1:8000 (in use ...)").
  static Result<BundleServer> start(const std::string& bundle_path, const ServeOptions& options);
  ~BundleServer();   // stops, and removes the bundle's copy
  BundleServer(BundleServer&&) noexcept;
  BundleServer& operator=(BundleServer&&) noexcept;

  const std::string& url() const;             // "http://127.0.0.1:8000/"
  int port() const;
  const bundle::Manifest& manifest() const;
  std::uint64_t requests() const;             // answered so far
  std::string last_request() const;           // the newest log line, "" before the first
  void stop();                                // stops listening; answers no more (idempotent)
  void wait();                                // until stop() is called from another thread (or a signal ends it all)

 private:
  struct Impl;
  explicit BundleServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// How to open `url`'s page on a phone, in lines of plain text: over USB with `adb reverse tcp:PORT tcp:PORT`
// (Android's Chrome then reaches this computer's 127.0.0.1), or from any static HTTPS host.
std::string phone_advice(int port);

}  // namespace arwb::serve
