// Media as pixels: images decoded once and cached by path (here, media_store.cpp), video players (capture's
// VideoReader behind a clock, video_player.cpp), and the cards drawn for text and web links (cards.cpp). The
// scene asks the store on the worker thread; what it returns (MediaContent, track/media_spec.hpp) is then read
// by the UI thread to update textures, and by `arwb render` to composite offline.
//
// Live mode: each video decodes on its own thread, paced by its own frame rate, so a slow script or UI never
// stalls it. Offline mode: nothing runs in the background; set_clock decodes up to the asked time before it
// returns, so a render is the same every time.
#pragma once

#include "media/media_provider.hpp"
#include "media/model_cache.hpp"

#include <cstddef>
#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace arwb::media {

enum class StoreMode { live, offline };

// Versions (MediaContent::current) of everything the store returns come from one process-wide counter: they grow
// with each new picture of a content and are never shared by two contents, so a texture cache keyed by a
// content's address cannot mistake a new card or player at a recycled address for the old one.

class MediaStore final : public MediaProvider {
 public:
  explicit MediaStore(StoreMode mode);
  ~MediaStore();
  MediaStore(const MediaStore&) = delete;
  MediaStore& operator=(const MediaStore&) = delete;

  StoreMode mode() const { return mode_; }
  // An image (checked path, see media_path.hpp), decoded once and shared while anyone holds it: CV_8UC3 BGR, or
  // CV_8UC4 BGRA when the file has alpha (grey becomes BGR, 16-bit becomes 8-bit). Null and *error set on
  // failure, with load_image's message ("<path>: corrupt or truncated image data", "<path>: declares 9000x9000
  // pixels, more than the limit of 40000000"); *error cleared on success.
  std::shared_ptr<MediaContent> image(const std::string& path, std::string* error) override;
  // A new player for the video at `path` (each marker showing a video has its own position), showing its first
  // frame, which is decoded here. Live mode starts its decoding thread; it ends when the player is released.
  // Null and *error set when it cannot be used: "<path>: cannot open the video", "<path>: has no frames that
  // can be decoded", "<path>: frames of 9000x9000 pixels, more than 40000000"; *error cleared on success.
  std::shared_ptr<VideoContent> video(const std::string& path, bool loop, std::string* error) override;
  // A card with the text (several lines allowed), drawn with cairo in spec.font_px, spec.colour on
  // spec.background; cached by text and style, so a text that changes every frame costs one drawing per change.
  // Always a picture of at least 1x1 (empty text: the background alone). The text is cut to kMaxCardText bytes,
  // lines too long or too many for a kMaxCardSide square end with "…"; invalid UTF-8 shows as U+FFFD.
  std::shared_ptr<MediaContent> text_card(const MediaSpec& spec) override;
  // A card for a web link: a globe mark, the title in large type and the URL below it, "click to open".
  // kWebCardSize; the title is spec.title, else url_host(spec.url), else the URL.
  std::shared_ptr<MediaContent> web_card(const MediaSpec& spec) override;
  // The 3D model `relative` (as the scene wrote it) inside `scene_dir`: ModelCache::get.
  std::shared_ptr<const Mesh> model(const std::filesystem::path& scene_dir, const std::string& relative,
                                    std::string* error, std::string* warning = nullptr) override;
  // Forgets cached images, models and cards no one holds (after a scene reload).
  void trim() override;

  static constexpr size_t kMaxCardText = 4096;     // bytes of text drawn on one card
  static constexpr int kMaxCardSide = 4096;        // pixels
  static constexpr size_t kMaxCards = 256;         // cached cards; the least recently asked for go first
  static constexpr size_t kMaxCardBytes = 128u << 20;
  static constexpr int kWebCardWidth = 640, kWebCardHeight = 200;

 private:
  std::shared_ptr<MediaContent> cached_card(const std::string& key);  // null if absent; marks it recently used
  std::shared_ptr<MediaContent> remember_card(const std::string& key, std::shared_ptr<MediaContent> card);
  void evict_cards();  // mutex_ held

  StoreMode mode_;
  std::mutex mutex_;
  std::unordered_map<std::string, std::weak_ptr<MediaContent>> images_;
  ModelCache models_;
  std::unordered_map<std::string, std::shared_ptr<MediaContent>> cards_;
  std::list<std::string> card_order_;  // keys of cards_, least recently asked for first
  size_t card_bytes_ = 0;              // pixels held by cards_
};

}  // namespace arwb::media
