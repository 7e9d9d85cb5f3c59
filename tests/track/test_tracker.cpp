// Markers over time: enter once, held briefly when missed, leave after the hold.
#include "track/tracker.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arwb {
namespace {

Marker at(int id, float x, float s = 50) {
  Marker m;
  m.id = id;
  m.dict = "ARUCO_ORIGINAL";
  m.corners = {{{x, 100}, {x + s, 100}, {x + s, 100 + s}, {x, 100 + s}}};
  return m;
}

TrackerSettings unsmoothed() {
  TrackerSettings s;
  s.smoothing.on = false;   // corners exactly as detected
  return s;
}

TEST(Tracker, EntersHoldsAndLeaves) {
  Tracker t(unsmoothed());
  auto ev = t.update({at(7, 10), at(3, 200)}, 0.0);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].id, 3);
  EXPECT_EQ(ev[0].kind, TrackEvent::Kind::enter);
  EXPECT_EQ(ev[1].id, 7);
  ASSERT_EQ(t.tracks().size(), 2u);
  EXPECT_EQ(t.tracks()[0].id, 3);

  ev = t.update({at(7, 12)}, 0.1);   // 3 missed: held, no event
  EXPECT_TRUE(ev.empty());
  ASSERT_EQ(t.tracks().size(), 2u);
  EXPECT_FALSE(t.tracks()[0].detected);
  EXPECT_FLOAT_EQ(t.tracks()[0].corners[0].x, 200);   // its last corners
  EXPECT_TRUE(t.tracks()[1].detected);
  EXPECT_NEAR(t.tracks()[1].visible_s, 0.1, 1e-12);
  EXPECT_FLOAT_EQ(t.tracks()[1].corners[0].x, 12);

  ev = t.update({at(7, 13)}, 0.2);   // missed on two frames, for less than the hold: held
  EXPECT_TRUE(ev.empty());
  ev = t.update({at(7, 14)}, 0.4);   // 3 missed on three frames, for 0.4 s > hold: leaves
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, TrackEvent::Kind::leave);
  EXPECT_EQ(ev[0].id, 3);
  ASSERT_EQ(t.tracks().size(), 1u);

  ev = t.update({at(7, 14), at(3, 200)}, 0.5);   // back: a new visit starts at 0 s
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, TrackEvent::Kind::enter);
  EXPECT_NEAR(t.tracks()[0].visible_s, 0.0, 1e-12);
  EXPECT_NEAR(t.tracks()[1].visible_s, 0.5, 1e-12);
}

// A marker missed on a frame or two does not leave and enter again, at 4 fps as at 30 (at 4 fps one missed frame
// is half a second unseen); missed for longer than the hold and on more than two frames, it leaves once.
TEST(Tracker, AMarkerMissedOnAFrameOrTwoDoesNotFlapAt4Or30Fps) {
  for (const double fps : {4.0, 30.0}) {
    Tracker t(unsmoothed());
    int enters = 0, leaves = 0, frame = 0;
    auto step = [&](bool seen) {
      for (const TrackEvent& e : t.update(seen ? std::vector<Marker>{at(5, 100)} : std::vector<Marker>{}, frame++ / fps))
        (e.kind == TrackEvent::Kind::enter ? enters : leaves)++;
    };
    for (const bool seen : {true, true, false, true, true, false, false, true, true}) step(seen);
    EXPECT_EQ(enters, 1) << fps << " fps";
    EXPECT_EQ(leaves, 0) << fps << " fps";
    int missed = 0;
    while (leaves == 0 && missed < 100) step(false), ++missed;
    EXPECT_EQ(leaves, 1) << fps << " fps";
    // It left on the first frame both unseen past the hold (0.25 s) and missed on a third frame in a row.
    EXPECT_EQ(missed, std::max(3, int(std::floor(0.25 * fps)) + 1)) << fps << " fps";
  }
}

TEST(Tracker, CentreSideAndDuplicates) {
  Tracker t;
  // The same id twice: two tracks (once only the larger was tracked), in order of first appearance.
  t.update({at(5, 300, 80), at(5, 0, 20)}, 0);
  ASSERT_EQ(t.tracks().size(), 2u);
  EXPECT_EQ(t.tracks()[0].instance, 0);
  EXPECT_EQ(t.tracks()[1].instance, 1);
  EXPECT_NE(t.tracks()[0].track_id, t.tracks()[1].track_id);
  EXPECT_NEAR(t.tracks()[0].side_px, 80, 1e-9);
  EXPECT_NEAR(t.tracks()[0].centre.x, 340, 1e-9);
  EXPECT_NEAR(t.tracks()[0].centre.y, 140, 1e-9);
  EXPECT_NEAR(t.tracks()[1].side_px, 20, 1e-9);
}


Marker centred(int id, cv::Point2d c, double s = 50) {
  Marker m;
  m.id = id;
  m.dict = "ARUCO_ORIGINAL";
  const float h = float(s / 2), x = float(c.x), y = float(c.y);
  m.corners = {{{x - h, y - h}, {x + h, y - h}, {x + h, y + h}, {x - h, y + h}}};
  return m;
}

TEST(Tracker, TwoPrintsOfOneIdCrossingKeepTheirTracks) {
  Tracker t;
  // Two prints of id 4, 50 px wide, passing each other 60 px apart at 25 px a frame.
  // The detector's order says nothing about which print is which: it alternates here.
  auto frame = [](int k) {
    std::vector<Marker> v{centred(4, {100.0 + 25 * k, 200}), centred(4, {600.0 - 25 * k, 260})};
    if (k % 2) std::swap(v[0], v[1]);
    return v;
  };
  auto ev = t.update(frame(0), 0);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_NE(ev[0].track_id, ev[1].track_id);
  ASSERT_EQ(t.tracks().size(), 2u);
  const uint64_t upper = t.tracks()[0].raw_corners[0].y < 200 ? t.tracks()[0].track_id : t.tracks()[1].track_id;
  for (int k = 1; k <= 20; ++k) {
    ev = t.update(frame(k), k / 30.0);
    EXPECT_TRUE(ev.empty()) << "frame " << k;
    ASSERT_EQ(t.tracks().size(), 2u);
    for (const TrackedMarker& m : t.tracks())
      EXPECT_EQ(m.track_id == upper, m.raw_corners[0].y < 200) << "frame " << k << ": the tracks swapped";
  }
  // One leaves: the other keeps its track and becomes instance 0; a print that comes back is a new track.
  for (int k = 21; k <= 30; ++k) t.update({centred(4, {100.0 + 25 * k, 200})}, k / 30.0);
  ASSERT_EQ(t.tracks().size(), 1u);
  EXPECT_EQ(t.tracks()[0].track_id, upper);
  EXPECT_EQ(t.tracks()[0].instance, 0);
  ev = t.update({centred(4, {100.0 + 25 * 31, 200}), centred(4, {100, 400})}, 31 / 30.0);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_GT(ev[0].track_id, upper);
  EXPECT_EQ(t.tracks()[1].instance, 1);
}

// Frame-to-frame RMS motion of the corners of a still marker whose detections carry 0.5 px of noise.
TEST(Tracker, StillNoisyMarkerSteadierFiltered) {
  Tracker t;
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0, 0.5f);
  double raw = 0, filtered = 0;
  Quad last_raw{}, last_filtered{};
  for (int k = 0; k < 120; ++k) {
    Marker m = centred(1, {320, 240}, 80);
    for (auto& c : m.corners) c += cv::Point2f(noise(rng), noise(rng));
    t.update({m}, k / 30.0);
    const TrackedMarker& tr = t.tracks().at(0);
    if (k >= 30)   // after the filter settled
      for (size_t c = 0; c < 4; ++c) {
        raw += std::pow(cv::norm(tr.raw_corners[c] - last_raw[c]), 2);
        filtered += std::pow(cv::norm(tr.corners[c] - last_filtered[c]), 2);
      }
    last_raw = tr.raw_corners;
    last_filtered = tr.corners;
  }
  EXPECT_LT(filtered, 0.25 * raw);   // RMS under half the raw
  // Off: the corners are the detections.
  TrackerSettings off;
  off.smoothing.on = false;
  Tracker u(off);
  Marker m = centred(1, {320, 240}, 80);
  u.update({m}, 0);
  m.corners[0].x += 0.7f;
  u.update({m}, 1 / 30.0);
  EXPECT_FLOAT_EQ(u.tracks()[0].corners[0].x, m.corners[0].x);
}

TEST(Tracker, StepMoveFollowedWithinAFewFrames) {
  Tracker t;
  for (int k = 0; k < 30; ++k) t.update({centred(2, {200, 200})}, k / 30.0);
  int frames = 0;
  for (int k = 30; k < 60; ++k) {
    t.update({centred(2, {240, 200})}, k / 30.0);
    ++frames;
    if (std::abs(t.tracks()[0].centre.x - 240) < 0.5) break;
  }
  EXPECT_LE(frames, 5) << "a 40 px step took " << frames << " frames to be followed within 0.5 px";
  EXPECT_EQ(t.tracks().size(), 1u);
}

TEST(Tracker, PoseFromTheCameraAndChosenByThePrevious) {
  // A small marker (20 sides away, about 28 px) tilted 15 degrees: its corners under 0.1 px of noise often fit the
  // flipped pose better. The tracker keeps the pose its first, noise-free frame found.
  const Calibration cam = default_calibration({640, 480});
  PoseSolution truth;
  truth.rvec = cv::Vec3d(0, 15 * CV_PI / 180, 0);
  truth.tvec = cv::Vec3d(1, -0.5, 20);
  std::vector<cv::Point3d> obj;
  for (const auto& p : marker_object_points(1.0)) obj.push_back(p);
  const std::vector<cv::Point2d> exact = project_marker_points(obj, truth, cam);
  TrackerSettings s;
  s.smoothing.on = false;   // the pose of each frame's own corners
  Tracker t(s);
  t.update({centred(3, {0, 0})}, 0);
  EXPECT_FALSE(t.tracks()[0].pose) << "no camera, no pose";
  t.clear();
  t.set_camera(cam, 1.0);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.1);
  int raw_flips = 0, tracked_flips = 0, chosen = 0;
  for (int k = 0; k < 60; ++k) {
    Marker m;
    m.id = 3;
    for (size_t c = 0; c < 4; ++c)
      m.corners[c] = cv::Point2f(float(exact[c].x + (k ? noise(rng) : 0)), float(exact[c].y + (k ? noise(rng) : 0)));
    t.update({m}, k / 30.0);
    const TrackedMarker& tr = t.tracks().at(0);
    ASSERT_TRUE(tr.pose) << "frame " << k;
    const std::optional<MarkerPose> raw = estimate_marker_pose(m.corners, 1.0, cam);
    ASSERT_TRUE(raw);
    raw_flips += rotation_difference_deg(raw->pose.rvec, truth.rvec) > 10;
    tracked_flips += rotation_difference_deg(tr.pose->pose.rvec, truth.rvec) > 10;
    chosen += tr.pose->chosen_by_previous;
    EXPECT_TRUE(tr.pose->assumed_camera);
  }
  EXPECT_GT(raw_flips, 0) << "the sequence must have frames whose corners prefer the flip";
  EXPECT_EQ(tracked_flips, 0);
  EXPECT_EQ(chosen, raw_flips) << raw_flips << " frames preferred the flip";
}

}  // namespace
}  // namespace arwb
