// The pixels behind an instance's media: images and web cards loaded once per key, text cards, the instance's own
// video player (its clock is the marker's time in view), and the frame's stage pictures.
#include "media/contents.hpp"
#include "script/scene_runtime_impl.hpp"

#include <opencv2/imgproc.hpp>

namespace arwb::script {
namespace {

// The frame's stage picture as BGR or BGRA. Colour views are shared, not copied: each Frame draws its views into
// fresh buffers and never touches them after it is published.
std::shared_ptr<MediaContent> make_stage_content(const cv::Mat& view, uint64_t version) {
  if (view.empty() || view.depth() != CV_8U) return nullptr;
  auto m = std::make_shared<cv::Mat>();
  if (view.channels() == 1) cv::cvtColor(view, *m, cv::COLOR_GRAY2BGR);
  else if (view.channels() == 3 || view.channels() == 4) *m = view;
  else return nullptr;
  return std::make_shared<media::StillContent>(std::move(m), version);
}

}  // namespace

std::shared_ptr<MediaContent> SceneRuntime::Impl::content_for(
    Program& p, const Mapping& m, Instance& inst, const MediaSpec& spec, const SceneInput& in,
    std::array<std::shared_ptr<MediaContent>, kStageCount>& stages) {
  const std::string at = p.display + ":" + std::to_string(m.line) + ": ";
  if (spec.kind != MediaKind::video && inst.video) {   // the media changed away from a video
    inst.video->set_clock(inst.position, false);
    inst.video.reset();
    inst.video_key.clear();
  }
  std::string err;
  switch (spec.kind) {
    case MediaKind::none:
    case MediaKind::cube:
    case MediaKind::axes:
    case MediaKind::model: return nullptr;   // 3D media have meshes (scene_solid.cpp), not pictures
    case MediaKind::image: {
      const std::string key = "image\n" + spec.path;
      if (inst.content_key != key) {
        inst.content_key = key;
        inst.content = store.image(spec.path, &err);
        inst.load_error = inst.content ? "" : err.empty() ? spec.source + ": cannot be loaded" : err;
        if (!inst.content) report(2, at + inst.load_error);
      }
      if (!inst.content) inst.error = inst.load_error;
      return inst.content;
    }
    case MediaKind::web: {
      const std::string key = "web\n" + spec.url + "\n" + spec.title;
      if (inst.content_key != key) {
        inst.content_key = key;
        inst.content = store.web_card(spec);
      }
      return inst.content;
    }
    case MediaKind::text: return store.text_card(spec);
    case MediaKind::video: {
      const std::string key = "video\n" + spec.path + (spec.loop ? "\nloop" : "");
      if (inst.video_key != key) {
        inst.video_key = key;
        inst.position = 0;
        inst.video = store.video(spec.path, spec.loop, &err);
        if (!inst.video) report(2, at + (err.empty() ? spec.source + ": cannot be played" : err));
      }
      if (!inst.video) {
        inst.error = "cannot play " + spec.source;
        return nullptr;
      }
      inst.video->set_clock(inst.position, true);
      if (std::string e = inst.video->error(); !e.empty()) {
        report(2, at + e);
        inst.error = e;
      }
      return inst.video;
    }
    case MediaKind::stage: {
      Stage s{};
      if (!stage_from_name(spec.stage, &s) || static_cast<int>(s) >= kStageCount) return nullptr;
      const size_t k = static_cast<size_t>(s);
      if (!stages[k] && in.views) stages[k] = make_stage_content((*in.views)[k], in.frame_index);
      if (!stages[k] && !p.stage_note) {
        p.stage_note = true;
        report(1, at + "stage \"" + spec.stage + "\" has no picture on this frame (stage pictures need the "
                       "trace at level full); nothing shown");
      }
      return stages[k];
    }
  }
  return nullptr;
}

}  // namespace arwb::script
