#include "peers/peers.hpp"

#include "detect/dictionary.hpp"

#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h10.h>
#include <apriltag/tag36h11.h>
}

#include <chrono>
#include <stdexcept>

namespace arwb {
namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }
}  // namespace

// [SECTION] OpenCV aruco

struct OpenCvArucoPeer::Impl {
  std::string name;
  cv::Ptr<cv::aruco::Dictionary> dict;
  cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
};

OpenCvArucoPeer::OpenCvArucoPeer(const std::string& dict_name, bool aruco3) : impl_(std::make_shared<Impl>()) {
  std::string err;
  auto d = dictionary_by_name(dict_name, &err);
  if (!d) throw std::runtime_error(err);
  impl_->name = d->name();
  impl_->params->useAruco3Detection = aruco3;
  // OpenCV's predefined tables, by the same names (ARUCO_ORIGINAL is OpenCV's own copy of the paper's).
  static const std::pair<const char*, cv::aruco::PREDEFINED_DICTIONARY_NAME> names[] = {
      {"ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL}, {"4X4_50", cv::aruco::DICT_4X4_50},
      {"4X4_100", cv::aruco::DICT_4X4_100}, {"4X4_250", cv::aruco::DICT_4X4_250},
      {"4X4_1000", cv::aruco::DICT_4X4_1000}, {"5X5_50", cv::aruco::DICT_5X5_50},
      {"5X5_100", cv::aruco::DICT_5X5_100}, {"5X5_250", cv::aruco::DICT_5X5_250},
      {"5X5_1000", cv::aruco::DICT_5X5_1000}, {"6X6_50", cv::aruco::DICT_6X6_50},
      {"6X6_100", cv::aruco::DICT_6X6_100}, {"6X6_250", cv::aruco::DICT_6X6_250},
      {"6X6_1000", cv::aruco::DICT_6X6_1000}, {"7X7_50", cv::aruco::DICT_7X7_50},
      {"7X7_100", cv::aruco::DICT_7X7_100}, {"7X7_250", cv::aruco::DICT_7X7_250},
      {"7X7_1000", cv::aruco::DICT_7X7_1000}, {"APRILTAG_16h5", cv::aruco::DICT_APRILTAG_16h5},
      {"APRILTAG_25h9", cv::aruco::DICT_APRILTAG_25h9}, {"APRILTAG_36h10", cv::aruco::DICT_APRILTAG_36h10},
      {"APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11}};
  for (const auto& [n, which] : names)
    if (impl_->name == n) impl_->dict = cv::aruco::getPredefinedDictionary(which);
  if (!impl_->dict) throw std::runtime_error("OpenCV has no dictionary " + impl_->name);
}

PeerResult OpenCvArucoPeer::detect(const cv::Mat& bgr) const {
  PeerResult r;
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  const auto t0 = Clock::now();
  cv::aruco::detectMarkers(bgr, impl_->dict, corners, ids, impl_->params);
  r.ms = ms_since(t0);
  for (size_t i = 0; i < ids.size(); ++i) {
    Marker m;
    m.id = ids[i];
    m.dict = impl_->name;
    for (int k = 0; k < 4; ++k) m.corners[size_t(k)] = corners[i][size_t(k)];
    r.markers.push_back(m);
  }
  return r;
}

// [SECTION] AprilTag

struct AprilTagPeer::Impl {
  std::string name;
  apriltag_family_t* family = nullptr;
  void (*destroy_family)(apriltag_family_t*) = nullptr;
  apriltag_detector_t* detector = nullptr;
  ~Impl() {
    if (detector) apriltag_detector_destroy(detector);
    if (family) destroy_family(family);
  }
};

bool AprilTagPeer::supports(const std::string& dict_name) {
  std::string err;
  auto d = dictionary_by_name(dict_name, &err);
  return d && d->name().rfind("APRILTAG_", 0) == 0;
}

AprilTagPeer::AprilTagPeer(const std::string& dict_name) : impl_(std::make_shared<Impl>()) {
  if (!supports(dict_name)) throw std::runtime_error("AprilTag has no family for " + dict_name);
  impl_->name = dictionary_by_name(dict_name)->name();
  if (impl_->name == "APRILTAG_16h5") impl_->family = tag16h5_create(), impl_->destroy_family = tag16h5_destroy;
  if (impl_->name == "APRILTAG_25h9") impl_->family = tag25h9_create(), impl_->destroy_family = tag25h9_destroy;
  if (impl_->name == "APRILTAG_36h10") impl_->family = tag36h10_create(), impl_->destroy_family = tag36h10_destroy;
  if (impl_->name == "APRILTAG_36h11") impl_->family = tag36h11_create(), impl_->destroy_family = tag36h11_destroy;
  impl_->detector = apriltag_detector_create();  // AprilTag's defaults, one thread
  impl_->detector->nthreads = 1;
  apriltag_detector_add_family(impl_->detector, impl_->family);
}

PeerResult AprilTagPeer::detect(const cv::Mat& bgr) const {
  PeerResult r;
  const auto t0 = Clock::now();
  cv::Mat grey;
  if (bgr.channels() == 1) grey = bgr;
  else cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  image_u8_t im{grey.cols, grey.rows, static_cast<int>(grey.step), grey.data};
  zarray_t* dets = apriltag_detector_detect(impl_->detector, &im);
  r.ms = ms_since(t0);
  for (int i = 0; i < zarray_size(dets); ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(dets, i, &det);
    Marker m;
    m.id = det->id;
    m.dict = impl_->name;
    m.hamming = det->hamming;
    // AprilTag wraps its corners the other way round from another start: OpenCV's corner k is AprilTag's
    // p[(5 - k) % 4]. AprilTag puts pixel centres at half-integers; arwb and OpenCV at integers.
    for (int k = 0; k < 4; ++k) {
      const double* p = det->p[(5 - k) % 4];
      m.corners[size_t(k)] = cv::Point2f(float(p[0] - 0.5), float(p[1] - 0.5));
    }
    r.markers.push_back(m);
  }
  apriltag_detections_destroy(dets);
  return r;
}

}  // namespace arwb
