// The scene's media as a phone's browser sees them, when a bundle gets the phone page (--web): what it would not
// show or play is said with the file named (a warning) or, with --convert-for-phones, copied into a form it does,
// beside the original: pictures as PNG by OpenCV, videos as MP4/H.264 by Debian's ffmpeg. The desktop player keeps
// the originals; the manifest's phone_media says which copy stands for which file, for the page to draw the copies
// once it draws media.
#include "bundle/export_parts.hpp"
#include "bundle/bundle_files.hpp"

#include "base/files.hpp"
#include "base/process.hpp"
#include "base/temp_dir.hpp"
#include "capture/image_header.hpp"
#include "capture/image_io.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>

namespace arwb::bundle {

namespace {

namespace fs = std::filesystem;

std::string fourcc_text(double value) {
  if (!(value > 0) || value > 4294967295.0) return "";   // OpenCV's -1: it cannot say
  const auto v = static_cast<std::uint32_t>(value);
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((v >> (8 * i)) & 0xFF);
    if (c >= 0x20 && c < 0x7F) s += c;
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// The ISO base media file's major brand ("isom", "mp42", "qt  "), "" when the file does not start with an ftyp box.
std::string ftyp_brand(const std::string& file) {
  std::array<char, 12> head{};
  std::ifstream in(file, std::ios::binary);
  if (!in.read(head.data(), head.size()) || std::string(head.data() + 4, 4) != "ftyp") return "";
  return std::string(head.data() + 8, 4);
}

// Every phone's browser plays H.264 in 8-bit 4:2:0 in an MP4 file: Safari on iPhones plays no WebM or AVI, Chrome
// no MPEG-4 Part 2, and no browser H.264 in 4:4:4 or 10 bits. OpenCV's FFmpeg backend reads the codec's tag and
// pixel format.
std::string video_problem(const std::string& file) {
  const std::string brand = ftyp_brand(file);
  cv::VideoCapture video(file, cv::CAP_FFMPEG);
  if (!video.isOpened()) return "a video OpenCV cannot open";
  const std::string codec = fourcc_text(video.get(cv::CAP_PROP_FOURCC));
  const std::string pixels = fourcc_text(video.get(cv::CAP_PROP_CODEC_PIXEL_FORMAT));
  const std::string shown = codec.empty() ? "" : " (" + codec + ")";
  if (brand.empty() || brand == "qt  ")
    return std::string(brand.empty() ? "not an MP4 file" : "a QuickTime file") + shown +
           ": phones' browsers play MP4 with H.264";
  static constexpr std::array<const char*, 4> kH264{"avc1", "h264", "H264", "x264"};
  if (std::find(kH264.begin(), kH264.end(), codec) == kH264.end())
    return "an MP4 file" + (shown.empty() ? std::string(" in a codec OpenCV does not name") : " in " + codec) +
           ": phones' browsers play H.264";
  if (pixels != "I420" && pixels != "YV12" && pixels != "NV12")
    return "H.264 in " + (pixels.empty() ? std::string("an unnamed pixel format") : pixels) +
           ": phones' browsers play 8-bit 4:2:0 (yuv420p)";
  return "";
}

Result<std::string> picture_for_phones(const std::string& file) {
  LoadedImage loaded = load_image(file, cv::IMREAD_UNCHANGED, kDefaultMaxPixels);
  if (!loaded.ok()) return fail(loaded.error);
  cv::Mat image = loaded.image;
  const int side = std::max(image.cols, image.rows);
  if (side > kPhoneMaxImageSide) {
    const double s = double(kPhoneMaxImageSide) / side;
    cv::resize(image, image, {std::max(1, int(image.cols * s)), std::max(1, int(image.rows * s))}, 0, 0,
               cv::INTER_AREA);
  }
  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", image, png)) return fail(file + ": cannot be written as PNG");
  return std::string(png.begin(), png.end());
}

Result<std::string> video_for_phones(const std::string& file, const std::string& shown) {
  Result<TempDir> scratch = TempDir::make("", "arwb-phone");
  if (!scratch) return fail(scratch.error());
  const std::string out = (scratch->path() / "phone.mp4").string();
  // Even sides (4:2:0 halves them), the first video and audio streams, the index at the front so that a phone
  // starts playing before the whole file has come.
  Result<ProcessResult> run = run_program({"ffmpeg", "-nostdin", "-hide_banner", "-loglevel", "error", "-i", file,
                                           "-map", "0:v:0", "-map", "0:a:0?", "-vf",
                                           "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-c:v", "libx264", "-preset",
                                           "veryfast", "-crf", "20", "-pix_fmt", "yuv420p", "-c:a", "aac", "-b:a",
                                           "128k", "-movflags", "+faststart", "-y", out});
  if (!run) return fail("--convert-for-phones: " + run.error() + " (Debian: apt install ffmpeg)");
  if (run->exit_status != 0) {
    std::string said = run->output.substr(0, run->output.find('\n'));
    return fail(shown + ": ffmpeg could not convert it (exit status " + std::to_string(run->exit_status) + ")" +
                (said.empty() ? "" : ": " + said));
  }
  if (const std::string still = video_problem(out); !still.empty())
    return fail(shown + ": ffmpeg's copy is still " + still);
  return read_whole_file(out, kMaxSourceBytes, false);
}

}  // namespace

std::string phone_problem(const std::string& file) {
  switch (classify_path(file)) {
    case PathKind::image: {
      const std::optional<ImageHeader> h = read_image_header(file);
      if (!h) return "";   // the desktop's own checks say what is wrong with it
      return phone_picture_problem(*h);
    }
    case PathKind::video: return video_problem(file);
    default: return "";
  }
}

Status add_phone_media(ExportPlan& plan) {
  const bool convert = plan.options.convert_for_phones;
  for (const auto& [path, source] : plan.sources) {
    if (path.rfind("scene/", 0) != 0 || path == plan.manifest.scene) continue;
    const std::string problem = phone_problem(source);
    if (problem.empty()) continue;
    if (!convert) {
      plan.warnings.push_back(path + ": " + problem + "; --convert-for-phones makes a copy they play");
      continue;
    }
    const bool video = classify_path(source) == PathKind::video;
    say(plan.options, "converting " + path + " for phones (" + problem + ")" + (video ? " with ffmpeg" : ""));
    Result<std::string> bytes = video ? video_for_phones(source, path) : picture_for_phones(source);
    if (!bytes) return fail(bytes.error());
    const std::string copy = "web/phone/" + path + (video ? ".mp4" : ".png");
    plan.manifest.phone_media.push_back({path, copy, problem});
    plan.generated.emplace_back(copy, std::move(*bytes));
  }
  return {};
}

}  // namespace arwb::bundle
