// BundleServer: a bundle's phone page on 127.0.0.1, asked with httplib's client as a browser would ask.
#include "serve/bundle_server.hpp"

#include "support/support.hpp"

#include <gtest/gtest.h>
#include <httplib.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace arwb::serve {
namespace {

namespace fs = std::filesystem;
using arwb::test::read_file;
using arwb::test::write_file;

// The museum exported to `out`, with a stand-in for the phone player's site (its files' bytes are their names) when
// `web`.
void export_museum(const fs::path& work, const fs::path& out, bool web) {
  fs::copy(fs::path(ARWB_SOURCE_DIR) / "scripts/museum", work / "museum", fs::copy_options::recursive);
  bundle::ExportOptions o;
  o.scene = (work / "museum/museum.lua").string();
  o.out = out.string();
  if (web) {
    const fs::path site = work / "site";
    for (const char* f : {"index.html", "sw.js", "web/player.js", "web/arwb_core.wasm"}) {
      fs::create_directories((site / f).parent_path());
      write_file((site / f).string(), std::string("the bytes of ") + f);
    }
    o.web_site = site.string();
  }
  Result<bundle::ExportPlan> plan = bundle::plan_export(o);
  ASSERT_TRUE(plan.ok()) << plan.error();
  ASSERT_TRUE(bundle::write_export(*plan).ok());
}

ServeOptions any_port() {
  ServeOptions o;
  o.port = 0;
  return o;
}

TEST(BundleServer, ServesEveryListedFileAsExportedAndNothingElse) {
  test::TempDir work;
  const fs::path out = work.path() / "museum-web";
  export_museum(work.path(), out, true);
  std::mutex mutex;
  std::vector<std::string> log;
  ServeOptions o = any_port();
  o.log = [&](const std::string& line) {
    std::lock_guard lock(mutex);
    log.push_back(line);
  };
  auto server = BundleServer::start(out.string(), o);
  ASSERT_TRUE(server.ok()) << server.error();
  BundleServer& s = *server;
  EXPECT_GT(s.port(), 0);
  EXPECT_EQ(s.url(), "http://127.0.0.1:" + std::to_string(s.port()) + "/");

  httplib::Client client("127.0.0.1", s.port());
  // The page at the root, every listed file with its bytes, and the manifest.
  auto root = client.Get("/");
  ASSERT_TRUE(root) << httplib::to_string(root.error());
  EXPECT_EQ(root->status, 200);
  EXPECT_EQ(root->body, "the bytes of index.html");
  EXPECT_EQ(root->get_header_value("Content-Type"), "text/html; charset=utf-8");
  for (const bundle::BundleFile& f : s.manifest().files) {
    auto r = client.Get("/" + f.path);
    ASSERT_TRUE(r) << f.path;
    EXPECT_EQ(r->status, 200) << f.path;
    EXPECT_EQ(r->body, read_file((out / f.path).string())) << f.path;
  }
  EXPECT_EQ(client.Get("/web/arwb_core.wasm")->get_header_value("Content-Type"), "application/wasm");
  EXPECT_EQ(client.Get("/sw.js?manifest=0123")->body, "the bytes of sw.js");
  EXPECT_EQ(client.Get("/manifest.json")->body, read_file((out / "manifest.json").string()));

  // A range, as a video element asks; one ending past the end ends at the last byte; one starting past it is 416.
  auto part = client.Get("/web/arwb_core.wasm", {{"Range", "bytes=4-8"}});
  ASSERT_TRUE(part);
  EXPECT_EQ(part->status, 206);
  EXPECT_EQ(part->body, "bytes");
  part = client.Get("/web/arwb_core.wasm", {{"Range", "bytes=17-999"}});
  ASSERT_TRUE(part);
  EXPECT_EQ(part->status, 206);
  EXPECT_EQ(part->body, "arwb_core.wasm");
  part = client.Get("/web/arwb_core.wasm", {{"Range", "bytes=999-"}});
  ASSERT_TRUE(part);
  EXPECT_EQ(part->status, 416);
  EXPECT_EQ(part->get_header_value("Content-Range"), "bytes */31");

  // Not listed: a file beside the bundle, outside it, or a folder.
  for (const char* path : {"/nothing.html", "/../museum/museum.lua", "/%2e%2e/museum/museum.lua", "/web/../index.html",
                           "/scene", "/web/"}) {
    auto r = client.Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 404) << path;
  }
  // Each request is logged by the thread that answered it, after answering: all of them, in any order, soon.
  const std::uint64_t made = s.manifest().files.size() + 13;
  for (int i = 0; i < 500 && s.requests() < made; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(s.requests(), made);
  {
    std::lock_guard lock(mutex);
    EXPECT_EQ(log.size(), made);
    for (const char* line : {"GET / 200 23 B", "GET /web/arwb_core.wasm 206 31 B", "GET /web/ 404"})
      EXPECT_NE(std::find(log.begin(), log.end(), line), log.end()) << line;
    EXPECT_NE(std::find(log.begin(), log.end(), s.last_request()), log.end()) << s.last_request();
  }

  // Stopped: nothing answers any more.
  s.stop();
  httplib::Client after("127.0.0.1", s.port());
  after.set_connection_timeout(1);
  EXPECT_FALSE(after.Get("/"));
}

// What is served is the copy verified as the server started: changing the exported folder afterwards changes
// nothing a browser gets.
TEST(BundleServer, ServesTheVerifiedCopyNotTheFolderAsItIsNow) {
  test::TempDir work;
  const fs::path out = work.path() / "museum-web";
  export_museum(work.path(), out, true);
  ServeOptions o = any_port();
  auto server = BundleServer::start(out.string(), o);
  ASSERT_TRUE(server.ok()) << server.error();
  write_file((out / "index.html").string(), "changed after the start");
  httplib::Client client("127.0.0.1", server->port());
  EXPECT_EQ(client.Get("/")->body, "the bytes of index.html");
}

TEST(BundleServer, RefusesBundlesWithoutAPageOrThatFailTheirCheck) {
  test::TempDir work;
  const fs::path plain = work.path() / "plain";
  export_museum(work.path(), plain, false);
  ServeOptions o = any_port();
  EXPECT_EQ(BundleServer::start(plain.string(), o).error(),
            plain.string() + ": has no web page; export it again with --web");

  const fs::path web = work.path() / "web";
  fs::remove_all(work.path() / "museum");
  export_museum(work.path(), web, true);
  write_file((web / "web/player.js").string(), "tampered");
  const std::string e = BundleServer::start(web.string(), o).error();
  EXPECT_NE(e.find("web/player.js: changed since export"), std::string::npos) << e;
}

TEST(BundleServer, APortInUseIsNamedOrAnotherIsTakenWhenAllowed) {
  test::TempDir work;
  const fs::path out = work.path() / "museum-web";
  export_museum(work.path(), out, true);
  ServeOptions o = any_port();
  auto first = BundleServer::start(out.string(), o);
  ASSERT_TRUE(first.ok()) << first.error();
  o.port = first->port();
  EXPECT_EQ(BundleServer::start(out.string(), o).error(),
            "cannot listen on 127.0.0.1:" + std::to_string(o.port) +
                " (in use by another program, or below 1024 without root)");
  o.any_port_if_taken = true;
  auto second = BundleServer::start(out.string(), o);
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_NE(second->port(), o.port);
  httplib::Client client("127.0.0.1", second->port());
  EXPECT_EQ(client.Get("/")->status, 200);
}

}  // namespace
}  // namespace arwb::serve
