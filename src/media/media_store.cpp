#include "media/media_store.hpp"

#include "capture/image_io.hpp"
#include "capture/pixels.hpp"
#include "media/cards.hpp"
#include "media/contents.hpp"
#include "media/media_path.hpp"
#include "media/video_player.hpp"

#include <algorithm>
#include <atomic>
#include <cstdio>

namespace arwb::media {

namespace {

// Exact, so two styles that differ in the last bit are different cards.
std::string key_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

size_t card_bytes(const MediaContent& card) {
  const cv::Size s = card.size();
  return static_cast<size_t>(s.area()) * 4;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// MediaStore

MediaStore::MediaStore(StoreMode mode) : mode_(mode) {}
MediaStore::~MediaStore() = default;

std::shared_ptr<MediaContent> MediaStore::image(const std::string& path, std::string* error) {
  {
    std::lock_guard lock(mutex_);
    if (auto it = images_.find(path); it != images_.end())
      if (std::shared_ptr<MediaContent> held = it->second.lock()) {
        if (error) error->clear();
        return held;
      }
  }
  // Decoded without the lock: a large image must not stall the cards.
  LoadedImage loaded = load_image(path, cv::IMREAD_UNCHANGED, kMaxMediaPixels);
  if (!loaded.ok()) {
    if (error) *error = loaded.error;
    return nullptr;
  }
  std::shared_ptr<MediaContent> content = std::make_shared<StillContent>(to_bgr8(loaded.image, Alpha::keep));
  std::lock_guard lock(mutex_);
  std::weak_ptr<MediaContent>& slot = images_[path];
  if (std::shared_ptr<MediaContent> raced = slot.lock()) content = std::move(raced);  // decoded twice: keep one
  else slot = content;
  if (error) error->clear();
  return content;
}

std::shared_ptr<const Mesh> MediaStore::model(const std::filesystem::path& scene_dir, const std::string& relative,
                                              std::string* error, std::string* warning) {
  return models_.get(scene_dir, relative, error, warning);
}

std::shared_ptr<VideoContent> MediaStore::video(const std::string& path, bool loop, std::string* error) {
  return open_video_player(path, loop, mode_, error);
}

std::shared_ptr<MediaContent> MediaStore::text_card(const MediaSpec& spec) {
  std::string key = "text\x1f";
  key += key_number(spec.font_px);
  for (int i = 0; i < 4; ++i) {
    key += ',';
    key += key_number(spec.colour[i]);
    key += ',';
    key += key_number(spec.background[i]);
  }
  key += '\x1f';
  key += spec.text;
  if (auto card = cached_card(key)) return card;
  return remember_card(key, std::make_shared<StillContent>(draw_text_card(spec)));
}

std::shared_ptr<MediaContent> MediaStore::web_card(const MediaSpec& spec) {
  const std::string key = "web\x1f" + spec.title + "\x1f" + spec.url;
  if (auto card = cached_card(key)) return card;
  return remember_card(key, std::make_shared<StillContent>(draw_web_card(spec)));
}

std::shared_ptr<MediaContent> MediaStore::cached_card(const std::string& key) {
  std::lock_guard lock(mutex_);
  auto it = cards_.find(key);
  if (it == cards_.end()) return nullptr;
  // Most recently asked for goes last, so a card shown every frame is never the one dropped.
  if (card_order_.back() != key) {
    card_order_.remove(key);
    card_order_.push_back(key);
  }
  return it->second;
}

std::shared_ptr<MediaContent> MediaStore::remember_card(const std::string& key, std::shared_ptr<MediaContent> card) {
  std::lock_guard lock(mutex_);
  auto [it, inserted] = cards_.try_emplace(key, card);
  if (!inserted) return it->second;  // drawn by another thread meanwhile
  card_order_.push_back(key);
  card_bytes_ += card_bytes(*card);
  evict_cards();
  return card;
}

void MediaStore::evict_cards() {
  const auto over = [&] { return cards_.size() > kMaxCards || card_bytes_ > kMaxCardBytes; };
  // First the least recently asked for that no one holds, then, if still over, the least recently asked for.
  for (int pass = 0; pass < 2 && over(); ++pass) {
    for (auto key = card_order_.begin(); key != card_order_.end() && over();) {
      auto it = cards_.find(*key);
      if (pass == 0 && it->second.use_count() > 1) {
        ++key;
        continue;
      }
      card_bytes_ -= card_bytes(*it->second);
      cards_.erase(it);
      key = card_order_.erase(key);
    }
  }
}

void MediaStore::trim() {
  std::lock_guard lock(mutex_);
  std::erase_if(images_, [](const auto& entry) { return entry.second.expired(); });
  models_.trim();
  for (auto key = card_order_.begin(); key != card_order_.end();) {
    auto it = cards_.find(*key);
    if (it->second.use_count() > 1) {
      ++key;
      continue;
    }
    card_bytes_ -= card_bytes(*it->second);
    cards_.erase(it);
    key = card_order_.erase(key);
  }
}

}  // namespace arwb::media
