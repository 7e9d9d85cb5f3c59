#include "bundle_fixture.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

namespace arwb::bundle::fixture {

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    out.insert(e.path().lexically_relative(dir).generic_string() + (e.is_directory() ? "/" : ""));
  return out;
}

PrivateTmp::PrivateTmp() {
  const char* old = std::getenv("TMPDIR");
  if (old) old_ = old, had_ = true;
  setenv("TMPDIR", dir_.str().c_str(), 1);
}

PrivateTmp::~PrivateTmp() {
  if (had_) setenv("TMPDIR", old_.c_str(), 1);
  else unsetenv("TMPDIR");
}

fs::path copy_example(const std::string& name, const fs::path& into) {
  const fs::path to = into / name;
  fs::copy(kScripts / name, to, fs::copy_options::recursive);
  return to;
}

Status export_to(const fs::path& scene, const fs::path& out, const std::string& calib, bool force) {
  ExportOptions o;
  o.scene = scene.string();
  o.out = out.string();
  o.calibration = calib;
  o.force = force;
  Result<ExportPlan> plan = plan_export(o);
  if (!plan) return fail(plan.error());
  return write_export(*plan);
}

void export_museum(const fs::path& out) {
  arwb::test::TempDir src;
  const fs::path dir = copy_example("museum", src.path());
  const Status s = export_to(dir / "museum.lua", out);
  ASSERT_TRUE(s.ok()) << s.error();
}

}  // namespace arwb::bundle::fixture
