#include "render/texture.hpp"

#include <chrono>

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>

#include <opencv2/imgproc.hpp>

#include <utility>

namespace arwb::render {

Texture::~Texture() {
  if (id_ != 0) glDeleteTextures(1, &id_);
}

Texture::Texture(Texture&& o) noexcept
    : id_(std::exchange(o.id_, 0u)), width_(o.width_), height_(o.height_), version_(o.version_) {}

Texture& Texture::operator=(Texture&& o) noexcept {
  if (this != &o) {
    if (id_ != 0) glDeleteTextures(1, &id_);
    id_ = std::exchange(o.id_, 0u);
    width_ = o.width_;
    height_ = o.height_;
    version_ = o.version_;
  }
  return *this;
}

bool Texture::upload(const cv::Mat& image, uint64_t version, bool nearest, bool mipmaps) {
  if (image.empty() || image.depth() != CV_8U) return false;
  if (id_ != 0 && version == version_ && image.cols == width_ && image.rows == height_) return false;
  cv::Mat src = image.isContinuous() ? image : image.clone();
  GLenum format = GL_RED;
  if (src.channels() == 3) format = GL_BGR;
  else if (src.channels() == 4) format = GL_BGRA;
  if (id_ == 0) glGenTextures(1, &id_);
  glBindTexture(GL_TEXTURE_2D, id_);
  const GLint filter = nearest ? GL_NEAREST : GL_LINEAR;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, mipmaps ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (src.channels() == 1) {
    // Grey shows as grey, not red.
    const GLint swizzle[4] = {GL_RED, GL_RED, GL_RED, GL_ONE};
    glTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_RGBA, swizzle);
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  if (src.cols == width_ && src.rows == height_) {
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, src.cols, src.rows, format, GL_UNSIGNED_BYTE, src.data);
  } else {
    const GLint internal = src.channels() == 1 ? GL_R8 : (src.channels() == 4 ? GL_RGBA8 : GL_RGB8);
    glTexImage2D(GL_TEXTURE_2D, 0, internal, src.cols, src.rows, 0, format, GL_UNSIGNED_BYTE, src.data);
  }
  if (mipmaps) glGenerateMipmap(GL_TEXTURE_2D);
  width_ = src.cols;
  height_ = src.rows;
  version_ = version;
  return true;
}

Texture& TextureCache::get(const std::string& key, const cv::Mat& image, uint64_t version, bool nearest,
                           bool mipmaps) {
  Entry& e = entries_[key];
  e.last_used = frame_;
  const auto t0 = std::chrono::steady_clock::now();
  if (e.texture.upload(image, version, nearest, mipmaps)) {
    ++uploads_.count;
    uploads_.bytes += double(image.total() * image.elemSize());
    uploads_.ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  return e.texture;
}

void TextureCache::end_frame(int keep_frames) {
  ++frame_;
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (frame_ - it->second.last_used > static_cast<uint64_t>(keep_frames)) it = entries_.erase(it);
    else ++it;
  }
}

cv::Mat read_framebuffer(int width, int height) {
  cv::Mat rgba(height, width, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  cv::flip(bgr, bgr, 0);  // OpenGL's first row is the bottom one
  return bgr;
}

}  // namespace arwb::render
