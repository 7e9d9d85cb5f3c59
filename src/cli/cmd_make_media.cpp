// arwb make-media: paints the media the example scenes under scripts/ use (pictures for the museum, a short
// clip), so the examples need no downloads. The shipped files were made by this command; run it again to
// regenerate them (the output is the same every time).
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

namespace arwb {
namespace {

namespace fs = std::filesystem;

// A gilded frame around a picture: what makes a painting read as a painting on a small marker.
void frame_it(cv::Mat& img) {
  const int b = img.cols / 18;
  cv::rectangle(img, {0, 0}, {img.cols - 1, img.rows - 1}, cv::Scalar(40, 150, 200), b * 2);
  cv::rectangle(img, {b - 2, b - 2}, {img.cols - b + 1, img.rows - b + 1}, cv::Scalar(20, 90, 130), 3);
}

cv::Mat composition() {
  // In the manner of a grid painting: primaries between black bars.
  cv::Mat img(600, 480, CV_8UC3, cv::Scalar(235, 240, 242));
  auto block = [&](int x0, int y0, int x1, int y1, cv::Scalar c) { cv::rectangle(img, {x0, y0}, {x1, y1}, c, cv::FILLED); };
  block(40, 40, 250, 300, cv::Scalar(40, 40, 200));
  block(270, 320, 440, 560, cv::Scalar(160, 70, 20));
  block(40, 470, 160, 560, cv::Scalar(40, 200, 240));
  for (int x : {250, 270, 160}) cv::line(img, {x, 0}, {x, img.rows}, cv::Scalar(20, 20, 20), 14);
  for (int y : {300, 320, 470}) cv::line(img, {0, y}, {img.cols, y}, cv::Scalar(20, 20, 20), 14);
  frame_it(img);
  return img;
}

cv::Mat sunset() {
  // A landscape: sky gradient, sun, sea with reflections, hills.
  cv::Mat img(480, 720, CV_8UC3);
  for (int y = 0; y < img.rows; ++y) {
    const double t = double(y) / img.rows;
    const cv::Vec3b sky(uint8_t(120 + 60 * t), uint8_t(60 + 120 * t), uint8_t(200 + 50 * t));
    const cv::Vec3b sea(uint8_t(120 - 40 * t), uint8_t(70 - 20 * t), uint8_t(30));
    img.row(y).setTo(y < 300 ? cv::Scalar(sky) : cv::Scalar(sea));
  }
  cv::circle(img, {360, 260}, 70, cv::Scalar(60, 200, 255), cv::FILLED, cv::LINE_AA);
  for (int y = 305; y < 460; y += 12)
    cv::line(img, {360 - (460 - y) / 3, y}, {360 + (460 - y) / 3, y}, cv::Scalar(70, 190, 250), 3, cv::LINE_AA);
  std::vector<cv::Point> hill;
  for (int x = 0; x <= 720; x += 20) hill.push_back({x, 300 - int(40 * std::sin(x / 90.0) + 30)});
  hill.push_back({720, 300});
  hill.push_back({0, 300});
  cv::fillPoly(img, std::vector<std::vector<cv::Point>>{hill}, cv::Scalar(60, 50, 70), cv::LINE_AA);
  frame_it(img);
  return img;
}

cv::Mat flask() {
  // A lab label's icon: a conical flask, on transparent ground (PNG with alpha).
  cv::Mat img(256, 256, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  const std::vector<cv::Point> body{{108, 30}, {148, 30}, {148, 100}, {210, 220}, {46, 220}, {108, 100}};
  cv::fillPoly(img, std::vector<std::vector<cv::Point>>{body}, cv::Scalar(250, 250, 250, 230), cv::LINE_AA);
  const std::vector<cv::Point> liquid{{80, 160}, {176, 160}, {210, 220}, {46, 220}};
  cv::fillPoly(img, std::vector<std::vector<cv::Point>>{liquid}, cv::Scalar(90, 200, 60, 255), cv::LINE_AA);
  cv::polylines(img, std::vector<std::vector<cv::Point>>{body}, true, cv::Scalar(40, 40, 40, 255), 6, cv::LINE_AA);
  return img;
}

// Three seconds of a planet orbiting, with the frame number printed, so a viewer can see it play, pause and loop.
bool orbit(const std::string& path, std::string* error) {
  const int fps = 25, frames = 75;
  const cv::Size size(320, 240);
  cv::VideoWriter w;
  if (!open_video_writer(w, path, fps, size)) {
    *error = "FFmpeg cannot write MP4 here";
    return false;
  }
  for (int i = 0; i < frames; ++i) {
    cv::Mat img(size, CV_8UC3, cv::Scalar(40, 20, 10));
    for (int s = 0; s < 40; ++s)
      cv::circle(img, {(s * 73) % 320, (s * 151) % 240}, 1, cv::Scalar(255, 255, 255), cv::FILLED);
    const cv::Point c(160, 120);
    cv::circle(img, c, 28, cv::Scalar(60, 200, 255), cv::FILLED, cv::LINE_AA);
    cv::ellipse(img, c, {110, 60}, 0, 0, 360, cv::Scalar(120, 120, 120), 1, cv::LINE_AA);
    const double a = 2 * CV_PI * i / frames;
    const cv::Point p(c.x + int(110 * std::cos(a)), c.y + int(60 * std::sin(a)));
    cv::circle(img, p, 14, cv::Scalar(200, 120, 40), cv::FILLED, cv::LINE_AA);
    cv::putText(img, "frame " + std::to_string(i), {10, 228}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1,
                cv::LINE_AA);
    w.write(img);
  }
  return true;
}

}  // namespace

int cmd_make_media(int argc, char** argv) {
  CommandLine cl("arwb make-media",
                 "Paints the example scenes' media into DIR: museum/media/composition.png, museum/media/sunset.png, "
                 "museum/media/orbit.mp4 and lab/media/flask.png. Existing files are kept unless --force.");
  std::string out = "scripts";
  bool force = false;
  cl.app.add_option("--out", out, "the folder the example scenes live in")->type_name("DIR")->check(out_kinds({}, true));
  cl.app.add_flag("--force", force, "replace files that exist");
  if (const auto status = cl.parse(argc, argv)) return *status;
  int written = 0, kept = 0, failed = 0;
  auto target = [&](const std::string& rel) -> std::string {
    const fs::path p = fs::path(out) / rel;
    std::error_code ec;
    if (fs::exists(p, ec) && !force) {
      ++kept;
      return {};
    }
    fs::create_directories(p.parent_path(), ec);
    return p.string();
  };
  auto image = [&](const std::string& rel, const cv::Mat& img) {
    const std::string p = target(rel);
    if (p.empty()) return;
    if (cv::imwrite(p, img)) {
      ++written;
      std::printf("wrote %s (%dx%d)\n", p.c_str(), img.cols, img.rows);
    } else {
      ++failed;
      print_problem("arwb make-media: cannot write %s\n", p.c_str());
    }
  };
  image("museum/media/composition.png", composition());
  image("museum/media/sunset.png", sunset());
  image("lab/media/flask.png", flask());
  if (const std::string p = target("museum/media/orbit.mp4"); !p.empty()) {
    std::string err;
    if (orbit(p, &err)) {
      ++written;
      std::printf("wrote %s (320x240, 3 s at 25 fps)\n", p.c_str());
    } else {
      ++failed;
      print_problem("arwb make-media: %s: %s\n", p.c_str(), err.c_str());
    }
  }
  std::printf("%d written, %d kept (use --force to replace)%s\n", written, kept, failed ? ", some failed" : "");
  return failed ? 1 : 0;
}

}  // namespace arwb
