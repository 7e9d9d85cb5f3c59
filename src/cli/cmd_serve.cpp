// `arwb serve BUNDLE`: a bundle's phone page (exported with --web) on http://127.0.0.1:PORT/ for a browser on this
// computer, or on an Android phone through `adb reverse`; the address also as a QR code. The bundle is verified
// first, as `arwb play` verifies it, and only its manifest's files are served (serve/bundle_server.hpp).
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "base/text.hpp"
#include "serve/bundle_server.hpp"
#include "serve/qr_code.hpp"

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include <unistd.h>

namespace arwb {

int cmd_serve(int argc, char** argv) {
  CommandLine cl("arwb serve",
                 "Serves a bundle exported with --web (its phone page) on http://127.0.0.1:PORT/ and prints the "
                 "address, a QR code of it and how to open it on a phone. The bundle is verified against its "
                 "manifest first, and only the files the manifest lists are served. Ctrl+C stops.",
                 "A phone's browser gives the camera only to an HTTPS page or to 127.0.0.1: over USB, `adb reverse "
                 "tcp:PORT tcp:PORT` makes the phone's 127.0.0.1:PORT this server; otherwise put the bundle's files "
                 "on a static HTTPS host. Each request answered is logged to stderr (--quiet: none).");
  std::string bundle_path;
  serve::ServeOptions o;
  double seconds = 0;
  bool quiet = false;
  cl.app.add_option("BUNDLE", bundle_path, "the bundle: a folder, or a .arwb or .zip file, exported with --web")
      ->required();
  cl.app.add_option("--port", o.port, "the port on 127.0.0.1; 0: any free one")
      ->capture_default_str()
      ->type_name("P")
      ->check(whole_number(0, 65535));
  cl.app.add_option("--seconds", seconds, "stop after S seconds; 0: when stopped with Ctrl+C")
      ->type_name("S")
      ->check(real_number(0, 1e7));
  cl.app.add_flag("--quiet", quiet, "log no requests");
  if (const auto status = cl.parse(argc, argv)) return *status;

  if (!quiet) o.log = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  auto server = serve::BundleServer::start(bundle_path, o);
  if (!server) {
    const bool port_problem = server.error().rfind("cannot listen", 0) == 0;
    print_problem("arwb serve: %s%s\n", printable(server.error()).c_str(),
                  port_problem ? "; choose another with --port, or --port 0 for any free one" : "");
    return 1;
  }
  serve::BundleServer& s = *server;
  const bundle::Manifest& m = s.manifest();
  std::printf("Serving \"%s\" (%s: %zu marker%s of %s, %zu files) at\n\n    %s\n\n", printable(m.title).c_str(),
              printable(bundle_path).c_str(), m.ids.size(), m.ids.size() == 1 ? "" : "s", m.dictionary.c_str(),
              m.files.size() + 1, s.url().c_str());
  if (const auto qr = serve::make_qr(s.url())) std::printf("%s\n", serve::qr_terminal_text(*qr, ::isatty(1)).c_str());
  std::printf("%sCtrl+C stops.\n", serve::phone_advice(s.port()).c_str());
  std::fflush(stdout);
  if (seconds > 0) {
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    s.stop();
  } else {
    s.wait();
  }
  std::fprintf(stderr, "arwb serve: stopped after %llu request%s\n", static_cast<unsigned long long>(s.requests()),
               s.requests() == 1 ? "" : "s");
  return 0;
}

}  // namespace arwb
