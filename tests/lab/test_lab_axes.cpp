// The axes a plan file adds to the paper's (sides_px, tilts_deg, blurs_px, noises, occlusions): read and refused
// with their messages, each doing to the frames what it says (the side in pixels, the tilt of the marker's
// normal, the share covered), each costing recognition at its extreme, and left at their defaults changing nothing.
#include "lab/plan.hpp"
#include "lab_test_util.hpp"
#include "lab/cells_file.hpp"
#include "lab/run.hpp"
#include "lab/sensor.hpp"

#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

namespace arwb::lab {
namespace {

const double kFocal = default_lab_camera().camera_matrix(0, 0);

TEST(LabPlanAxes, APlanFileGivesTheAddedAxesAndCellsAreTheirProduct) {
  test::TempDir d;
  test::write_file(d.str("axes.yml"), "sides_px: [20, 40]\ndistances_m: [1, 2]\nlux: [1000, 500]\n"
                                      "tilts_deg: [0, 60]\nblurs_px: 1.5\nnoises: [0, 8]\nocclusions: [0, 0.4]\n");
  Result<LabPlan> p = read_plan(d.str("axes.yml"));
  ASSERT_TRUE(p) << p.error();
  EXPECT_EQ(p->sides_px, (std::vector<double>{20, 40}));
  EXPECT_EQ(p->tilts_deg, (std::vector<double>{0, 60}));
  EXPECT_EQ(p->blurs_px, (std::vector<double>{1.5}));
  EXPECT_EQ(p->noises, (std::vector<double>{0, 8}));
  EXPECT_EQ(p->occlusions, (std::vector<double>{0, 0.4}));
  const std::vector<Cell> cells = p->cells(kFocal);
  ASSERT_EQ(cells.size(), 2u * 2 * 2 * 1 * 2 * 2 * 2);
  EXPECT_EQ(p->cell_count(), cells.size());
  // Light innermost (a column per light level), the added axes between distance and light.
  EXPECT_EQ(cells[0].lux, 1000);
  EXPECT_EQ(cells[1].lux, 500);
  EXPECT_EQ(cells[1].occlusion, 0);
  EXPECT_EQ(cells[2].occlusion, 0.4);
  EXPECT_EQ(cells[4].noise, 8);
  EXPECT_EQ(cells[8].tilt_deg, 60);
  EXPECT_EQ(cells[16].distance_m, 2);
  EXPECT_EQ(cells[32].side_px, 40);
  for (const Cell& c : cells) {
    EXPECT_EQ(c.blur_px, 1.5);
    // The printed size is derived from the side through the camera: 20 px at 1 m is 36.1 mm.
    EXPECT_NEAR(marker_side_px(c.size_mm, c.distance_m, kFocal), c.side_px, 1e-9);
  }
  EXPECT_NEAR(cells[0].size_mm, 20 * 1000 / kFocal, 1e-9);
  // Cells differing only in an added axis share their frames' draws: the pose index of the paper's axes.
  EXPECT_EQ(p->pose_index(0), 0u);
  EXPECT_EQ(p->pose_index(1), 1u);
  EXPECT_EQ(p->pose_index(2), 0u);
  EXPECT_EQ(p->pose_index(15), 1u);
  EXPECT_EQ(p->pose_index(16), 2u);
  EXPECT_EQ(p->pose_index(63), 7u);
  // Every added axis not at its default is named, the blur too (one value, but not none).
  EXPECT_EQ(added_axes_text(*p, cells[15]), "tilt 60 blur 1.5 noise 8 occluded 0.4");
  // The paper's plan has none of them, and its pose index is the cell's own.
  const LabPlan paper = paper_plan();
  EXPECT_EQ(added_axes_text(paper, paper.cells(kFocal)[5]), "");
  for (size_t i = 0; i < paper.grid_count(); ++i) EXPECT_EQ(paper.pose_index(i), i);
}

// The report's blur and noise curves: after the grid, a cell per added blur and per added noise at curve_at, each
// the grid's cell there with only that factor changed, on its frames (its pose index).
TEST(LabPlanAxes, TheCurvesCellsAreTheGridsCellAtCurveAtWithOneFactorChanged) {
  const LabPlan paper = paper_plan();
  const std::vector<Cell> cells = paper.cells(kFocal);
  ASSERT_EQ(paper.grid_count(), 27u);
  ASSERT_EQ(cells.size(), 35u);
  ASSERT_EQ(paper.cell_count(), 35u);
  const long base = paper.curve_base();
  ASSERT_EQ(base, 14) << "39 mm (the second size), 1 m (the second distance), 500 lx (the third light)";
  EXPECT_EQ(cells[14].size_mm, 39);
  EXPECT_EQ(cells[14].distance_m, 1);
  EXPECT_EQ(cells[14].lux, 500);
  for (size_t i = 27; i < 35; ++i) {
    const bool blur = i < 31;
    EXPECT_EQ(cells[i].curve, blur ? kBlurCurve : kNoiseCurve) << i;
    EXPECT_EQ(cells[i].blur_px, blur ? paper.curve_blurs_px[i - 27] : 0) << i;
    EXPECT_EQ(cells[i].noise, blur ? 0 : paper.curve_noises[i - 31]) << i;
    EXPECT_EQ(cells[i].size_mm, 39);
    EXPECT_EQ(cells[i].distance_m, 1);
    EXPECT_EQ(cells[i].lux, 500);
    EXPECT_EQ(paper.pose_index(i), 14u) << "the base cell's frames";
  }
  EXPECT_EQ(paper.curves_text(), "8 cells for the blur and noise curves at 39 mm, 1 m, 500 lx");
  // Where there are none, and why.
  std::string why;
  LabPlan other = paper;
  other.sizes_mm = {80, 50};
  EXPECT_EQ(other.curve_base(&why), -1);
  EXPECT_EQ(why, "the grid has no cell at 39 mm, 1 m, 500 lx (curve_at)");
  EXPECT_EQ(other.cell_count(), other.grid_count());
  EXPECT_EQ(other.curves_text(), "");
  LabPlan added = paper;
  added.tilts_deg = {30};
  EXPECT_EQ(added.curve_base(&why), -1);
  EXPECT_EQ(why, "the plan has added axes of its own");
  // A plan file moves them, asks for none, or names what is wrong.
  test::TempDir d;
  test::write_file(d.str("moved.yml"), "curve_at: [65, 2, 1000]\ncurve_blurs_px: [1]\ncurve_noises: []\n");
  Result<LabPlan> moved = read_plan(d.str("moved.yml"));
  ASSERT_TRUE(moved) << moved.error();
  EXPECT_EQ(moved->curve_base(), 0);
  ASSERT_EQ(moved->cell_count(), 28u);
  EXPECT_EQ(moved->cells(kFocal)[27].blur_px, 1);
  test::write_file(d.str("none.yml"), "curve_blurs_px: []\ncurve_noises: []\n");
  Result<LabPlan> none = read_plan(d.str("none.yml"));
  ASSERT_TRUE(none) << none.error();
  EXPECT_EQ(none->cell_count(), 27u);
  const std::pair<const char*, const char*> bad[] = {
      {"curve_at: [40, 1, 500]\n", "curve_at: the grid has no cell at 40 mm, 1 m, 500 lx (curve_at)"},
      {"curve_at: [39, 1]\n", "curve_at: give [size_mm, distance_m, lux], three numbers"},
      {"curve_at: [39, -1, 500]\n", "curve_at: distances_m: value 1 (-1) must be a distance in m from 0.05 to 100"},
      {"curve_noises: [15, 300]\n", "curve_noises: value 2 (300) must be a noise sigma in grey levels from 0 to 100"},
  };
  for (const auto& [text, message] : bad) {
    test::write_file(d.str("bad.yml"), text);
    Result<LabPlan> r = read_plan(d.str("bad.yml"));
    ASSERT_FALSE(r) << text;
    EXPECT_EQ(r.error(), d.str("bad.yml") + ": " + message) << text;
  }
}

TEST(LabPlanAxes, MistakesInTheAddedAxesAreOneLineNamingTheField) {
  test::TempDir d;
  const std::pair<const char*, const char*> bad[] = {
      {"sides_px: [20]\nsizes_mm: [65]\n",
       "bad.yml: sides_px and sizes_mm: give one of them (sides_px derives the printed size)"},
      {"sides_px: [20, 2]\n", "bad.yml: sides_px: value 2 (2) must be a side in pixels from 4 to 2000"},
      {"tilts_deg: [30, 90]\n", "bad.yml: tilts_deg: value 2 (90) must be a tilt in degrees from 0 to 85"},
      {"blurs_px: [-1]\n", "bad.yml: blurs_px: value 1 (-1) must be a blur sigma in pixels from 0 to 20"},
      {"noises: [4, x]\n", "bad.yml: noises: value 2 is not a number"},
      {"occlusions: [0, 0.6]\n", "bad.yml: occlusions: value 2 (0.6) must be a share of the marker's area from 0 to 0.5"},
      {"occlusions: []\n", "bad.yml: occlusions: give 1 to 50 values"},
      {"side_px: [20]\n", "bad.yml: unknown field 'side_px' (did you mean 'sides_px'?)"},
      {"tilts_deg: [0, 10, 20, 30, 40, 50, 60, 70, 80]\nblurs_px: [0, 1, 2, 3, 4, 5]\nnoises: [0, 1, 2, 3, 4, 5]\n"
       "occlusions: [0, 0.1, 0.2, 0.3, 0.4]\n",
       "bad.yml: 43740 cells, more than 10000"},
  };
  for (const auto& [text, message] : bad) {
    test::write_file(d.str("bad.yml"), text);
    Result<LabPlan> p = read_plan(d.str("bad.yml"));
    ASSERT_FALSE(p) << text;
    EXPECT_EQ(p.error(), d.str("bad.yml") + std::string(message).substr(std::string("bad.yml").size())) << text;
  }
  // The panel's fields and lab_axis read the same lists with the same words.
  for (const PlanAxis& axis : plan_axes()) {
    if (std::string(axis.key) != "occlusions") continue;
    Result<std::vector<double>> v = parse_axis(axis, "0, 0.25");
    ASSERT_TRUE(v) << v.error();
    EXPECT_EQ(*v, (std::vector<double>{0, 0.25}));
    EXPECT_EQ(parse_axis(axis, "0.7").error(), "occlusions: value 1 (0.7) must be a share of the marker's area from 0 to 0.5");
  }
}

TEST(LabAxes, ASideInPixelsIsTheMarkersSideInTheFrame) {
  LabPlan p = one_cell(12);
  p.sides_px = {16, 30, 60};
  p.distances_m = {0.5, 2};
  p.tilts_deg = {0};   // facing the camera, so the side is the same all round
  const LabOptions o;
  LabFrameRenderer renderer(p, o, lab_marker_ids(p, o.seed));
  const std::vector<Cell> cells = p.cells(kFocal);
  ASSERT_EQ(cells.size(), 6u);
  const cv::Matx33d K = o.camera.camera_matrix;
  for (size_t ci = 0; ci < cells.size(); ++ci) {
    int measured = 0;
    for (int k = 0; k < p.frames_per_cell; ++k) {
      const LabFrame f = renderer.render(ci, k);
      if (!f.visible) continue;
      ++measured;
      double side = 0;
      for (size_t i = 0; i < 4; ++i) side += cv::norm(f.corners[(i + 1) % 4] - f.corners[i]) / 4;
      // A marker off the image centre at the same distance along its ray is nearer the image plane (depth
      // z = d cos(angle off the axis)), and so larger: its side at the centre is the side seen times z / d.
      const cv::Point2f c = (f.corners[0] + f.corners[1] + f.corners[2] + f.corners[3]) * 0.25f;
      const double rx = (c.x - K(0, 2)) / K(0, 0), ry = (c.y - K(1, 2)) / K(1, 1);
      const double at_centre = side / std::sqrt(1 + rx * rx + ry * ry);
      EXPECT_NEAR(at_centre, cells[ci].side_px, 0.05 * cells[ci].side_px) << "cell " << ci << " frame " << k;
      EXPECT_NEAR(f.tilt_deg, 0, 1e-9);
    }
    EXPECT_GE(measured, p.frames_per_cell / 2) << "cell " << ci;
  }
  // The run reports the side asked for, and the printed size it took.
  LabOptions one;
  one.detectors = {"arwb"};
  p.frames_per_cell = 2;
  const auto r = run_lab(p, one);
  ASSERT_TRUE(r) << r.error();
  EXPECT_NEAR(r->cells[0].side_px, 16, 1e-9);
  EXPECT_NEAR(r->cells[0].cell.size_mm, 16 * 0.5 * 1000 / kFocal, 1e-9);
  EXPECT_NE(lab_table_csv(*r).find("arwb,14.4338,0.5,1000,16.0,"), std::string::npos) << lab_table_csv(*r);
}

TEST(LabAxes, AFixedTiltIsTheAngleBetweenTheMarkersNormalAndTheCameraAxis) {
  LabPlan p = one_cell(15);
  p.tilts_deg = {0, 30, 60};
  const LabOptions o;
  LabFrameRenderer renderer(p, o, lab_marker_ids(p, o.seed));
  // The marker's corners in its own plane (OpenCV's order, x right, y up); the geometry is scale-free.
  const std::vector<cv::Point2f> square{{-0.5f, 0.5f}, {0.5f, 0.5f}, {0.5f, -0.5f}, {-0.5f, -0.5f}};
  const cv::Matx33d K_inv = o.camera.camera_matrix.inv();
  for (size_t ci = 0; ci < 3; ++ci) {
    std::vector<double> directions;
    for (int k = 0; k < p.frames_per_cell; ++k) {
      const LabFrame f = renderer.render(ci, k);
      if (!f.visible) continue;
      EXPECT_NEAR(f.tilt_deg, p.tilts_deg[ci], 1e-9);
      // The plane's orientation from the rendered corners alone (no lens distortion here): the homography from the
      // marker's plane to the image is K [r1 r2 t], so K^-1 H gives two of the plane's axes, and their cross
      // product its normal. (A PnP solver may pick the mirror pose of a small marker seen nearly face on.)
      const std::vector<cv::Point2f> image(f.corners.begin(), f.corners.end());
      const cv::Matx33d M = K_inv * cv::Matx33d(cv::getPerspectiveTransform(square, image));
      const cv::Vec3d r1(M(0, 0), M(1, 0), M(2, 0)), r2(M(0, 1), M(1, 1), M(2, 1));
      const cv::Vec3d normal = cv::normalize(r1.cross(r2));
      const double angle = std::acos(std::min(1.0, std::abs(normal[2]))) * 180 / CV_PI;
      EXPECT_NEAR(angle, p.tilts_deg[ci], 0.5) << "cell " << ci << " frame " << k;
      directions.push_back(std::atan2(f.tilt_y_deg, f.tilt_x_deg));
    }
    ASSERT_GE(directions.size(), 10u) << "cell " << ci;
    // The axis it turns about is random: the tilted cells' frames lean every way.
    if (p.tilts_deg[ci] > 0) {
      const auto [lo, hi] = std::minmax_element(directions.begin(), directions.end());
      EXPECT_GT(*hi - *lo, 2.0) << "cell " << ci;
    }
  }
  // A random tilt's angle is kept per frame in the cell, for recall against tilt.
  LabPlan random = one_cell(10);
  LabOptions one;
  one.detectors = {"arwb"};
  const auto r = run_lab(random, one);
  ASSERT_TRUE(r) << r.error();
  ASSERT_EQ(r->cells[0].tilts_deg.size(), 10u);
  LabFrameRenderer again(random, one, r->ids);
  for (int k = 0; k < 10; ++k) {
    const LabFrame f = again.render(0, k);
    EXPECT_NEAR(r->cells[0].tilts_deg[size_t(k)], f.visible ? f.tilt_deg : -1, 1e-4);
    if (f.visible) {
      EXPECT_NEAR(f.tilt_deg, std::hypot(f.tilt_x_deg, f.tilt_y_deg), 1e-9);
    }
  }
}

TEST(LabAxes, AnOccludedSideCoversItsShareAndCostsRecognition) {
  LabPlan p = one_cell(20);
  p.lux = {500};   // evening light: no shadow or glint (lighting.hpp), so the patch is all that differs
  p.occlusions = {0, 0.4};
  LabOptions o;
  o.detectors = {"arwb"};
  LabFrameRenderer renderer(p, o, lab_marker_ids(p, o.seed));
  int compared = 0;
  for (int k = 0; k < p.frames_per_cell; ++k) {
    const LabFrame clear = renderer.render(0, k), covered = renderer.render(1, k);
    ASSERT_EQ(clear.visible, covered.visible);
    if (!clear.visible) continue;
    // The same marker in the same place (the cells differ only in the occlusion), one side covered.
    EXPECT_EQ(clear.id, covered.id);
    for (size_t i = 0; i < 4; ++i) EXPECT_EQ(clear.corners[i], covered.corners[i]);
    EXPECT_FALSE(clear.light.shadow || clear.light.glare);
    EXPECT_EQ(clear.occluded_side, -1);
    EXPECT_GE(covered.occluded_side, 0);
    // The pixels of the marker the patch changed (the noise is drawn alike in both): about 40 % of its area.
    cv::Mat1b inside(clear.image.size(), uchar(0));
    std::vector<cv::Point> quad;
    for (const cv::Point2f& c : clear.corners) quad.emplace_back(int(std::lround(c.x)), int(std::lround(c.y)));
    cv::fillConvexPoly(inside, quad, cv::Scalar(255));
    cv::Mat diff;
    cv::absdiff(clear.image, covered.image, diff);
    cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
    const double changed = cv::countNonZero((diff > 20) & inside), area = cv::countNonZero(inside);
    EXPECT_NEAR(changed / area, 0.4, 0.08) << "frame " << k;
    ++compared;
  }
  EXPECT_GE(compared, 15);
  const auto r = run_lab(p, o);
  ASSERT_TRUE(r) << r.error();
  const double open = r->cells[0].detectors[0].p_rec(), occluded = r->cells[1].detectors[0].p_rec();
  EXPECT_GE(open, 80);
  EXPECT_LE(occluded, open - 40) << "P_Rec " << open << " % in the open, " << occluded << " % with 40 % covered";
}

TEST(LabAxes, MuchBlurOrNoiseCostsRecognition) {
  LabPlan p = one_cell(16);
  p.sizes_mm = {39};
  p.distances_m = {1};   // 22 px
  p.blurs_px = {0, 3};
  p.noises = {0, 60};
  LabOptions o;
  o.detectors = {"arwb", "opencv"};
  const auto r = run_lab(p, o);
  ASSERT_TRUE(r) << r.error();
  ASSERT_EQ(r->cells.size(), 4u);   // (blur 0, noise 0), (0, 60), (3, 0), (3, 60)
  for (size_t d = 0; d < o.detectors.size(); ++d) {
    SCOPED_TRACE(o.detectors[d]);
    const double plain = r->cells[0].detectors[d].p_rec(), noisy = r->cells[1].detectors[d].p_rec(),
                 blurred = r->cells[2].detectors[d].p_rec();
    EXPECT_GE(plain, 60);
    EXPECT_LE(noisy, plain - 30) << "noise 60 grey levels";
    EXPECT_LE(blurred, plain - 30) << "blur 3 px";
  }
  // The cell's whole blur holds the added one; the noise is on every frame, those without a marker too.
  EXPECT_GT(r->cells[2].blur_px, 3);
  EXPECT_LT(r->cells[0].blur_px, 3);
  EXPECT_NEAR(r->cells[2].blur_px, std::hypot(r->cells[0].blur_px, 3.0), 1e-9);
  LabFrameRenderer renderer(p, o, r->ids);
  const int empty = p.frames_per_cell;   // the first frame without a marker
  cv::Scalar mean, deviation;
  cv::Mat a, b;
  renderer.render(0, empty).image.convertTo(a, CV_32F);
  renderer.render(1, empty).image.convertTo(b, CV_32F);
  cv::meanStdDev(b - a, mean, deviation);
  EXPECT_NEAR(deviation[0], 60, 12);   // clipped at 0 and 255 in places, so a little under
}

// The paper's plan with the added axes stated at their defaults is the paper's plan: the same frames, the same
// table (the CSV apart from the times), and no added axis named in its rows.
TEST(LabAxes, TheAddedAxesAtTheirDefaultsChangeNothing) {
  test::TempDir d;
  test::write_file(d.str("stated.yml"), "blurs_px: [0]\nnoises: [0]\nocclusions: [0]\nframes_per_cell: 3\n");
  Result<LabPlan> stated = read_plan(d.str("stated.yml"));
  ASSERT_TRUE(stated) << stated.error();
  LabPlan paper = paper_plan();
  paper.frames_per_cell = 3;
  LabOptions o;
  o.detectors = {"arwb"};
  o.threads = 2;
  const auto a = run_lab(paper, o), b = run_lab(*stated, o);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(without_times(lab_table_csv(*a)), without_times(lab_table_csv(*b)));
  EXPECT_EQ(lab_table_text(*a), lab_table_text(*b));
  EXPECT_NE(lab_table_text(*a).find("\n 65 mm  2.0 m   18 px  "), std::string::npos) << lab_table_text(*a);
  for (size_t i = 0; i < a->cells.size(); ++i) EXPECT_EQ(a->cells[i].detectors[0].marks, b->cells[i].detectors[0].marks);
  // The CSV always has the added axes' columns, empty tilt for a random one.
  EXPECT_NE(lab_table_csv(*a).find(",false_positives,tilt_deg,added_blur_px,added_noise,occlusion,curve,median_ms\n"),
            std::string::npos);
  EXPECT_NE(lab_table_csv(*a).find(",,0,0,0,"), std::string::npos);
  // A resumed run takes no cell of another plan: the added axes are in the key.
  LabPlan tilted = paper;
  tilted.tilts_deg = {40};
  EXPECT_NE(lab_run_key(paper, o), lab_run_key(tilted, o));
  LabPlan occluded = paper;
  occluded.occlusions = {0.1};
  EXPECT_NE(lab_run_key(paper, o), lab_run_key(occluded, o));
}

// The text table names the added axes the plan has in its rows, and a saved cell carries them and its frames'
// tilts back.
TEST(LabAxes, RowsNameTheAddedAxesAndSavedCellsKeepThem) {
  LabPlan p = one_cell(3);
  p.tilts_deg = {0, 60};
  p.blurs_px = {1.5};
  p.lux = {1000, 500};
  LabOptions o;
  o.detectors = {"arwb"};
  std::vector<std::string> lines;
  const std::string key = lab_run_key(p, o);
  o.on_cell = [&](size_t i, const CellResult& c) { lines.push_back(cell_to_line(key, i, c)); };
  const auto r = run_lab(p, o);
  ASSERT_TRUE(r) << r.error();
  const std::string text = lab_table_text(*r);
  EXPECT_NE(text.find("\n 65 mm  0.5 m   72 px tilt 0  blur 1.5  "), std::string::npos) << text;
  EXPECT_NE(text.find("\n 65 mm  0.5 m   72 px tilt 60 blur 1.5  "), std::string::npos) << text;
  // The header is as wide as the rows' labels: the light levels stay over their columns.
  EXPECT_NE(text.find("\nsize, distance                                   1000 lx             500 lx\n"),
            std::string::npos) << text;
  ASSERT_EQ(lines.size(), 4u);
  const auto back = cell_from_line(key, lines[3], 1);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->first, 3u);
  EXPECT_EQ(back->second.cell.tilt_deg, 60);
  EXPECT_EQ(back->second.cell.blur_px, 1.5);
  EXPECT_EQ(back->second.cell.lux, 500);
  EXPECT_EQ(back->second.tilts_deg, r->cells[3].tilts_deg);
  EXPECT_EQ(back->second.tilts_deg.size(), 3u);
}

}  // namespace
}  // namespace arwb::lab
