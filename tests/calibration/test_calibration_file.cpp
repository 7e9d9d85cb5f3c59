// The calibration file reader accepts what OpenCV's samples, its interactive-calibration app, the paper and ROS
// write, refuses anything else with one line naming the file and the key, scales to a source of the same aspect
// ratio; the writer's files read back, and a failed write leaves nothing behind.
#include "calibration/calibration_file.hpp"

#include "support/support.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace arwb {
namespace {

using test::TempDir;
using test::write_file;

const char* kOpenCvSample = R"(%YAML:1.0
---
calibration_time: "Mon 23 Nov 2026"
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 560., 0., 322., 0., 555., 236., 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.25, 0.08, 0.001, -0.002, 0. ]
avg_reprojection_error: 0.21
)";

const char* kInteractive = R"(<?xml version="1.0"?>
<opencv_storage>
<calibrationDate>"Mon Nov 23 17:00:00 2026"</calibrationDate>
<framesCount>24</framesCount>
<cameraResolution>
  1280 720</cameraResolution>
<cameraMatrix type_id="opencv-matrix">
  <rows>3</rows>
  <cols>3</cols>
  <dt>d</dt>
  <data>
    900. 0. 640. 0. 905. 360. 0. 0. 1.</data></cameraMatrix>
<dist_coeffs type_id="opencv-matrix">
  <rows>1</rows>
  <cols>5</cols>
  <dt>d</dt>
  <data>
    0.1 -0.2 0. 0. 0.05</data></dist_coeffs>
<avg_reprojection_error>0.3</avg_reprojection_error>
</opencv_storage>
)";

const char* kRosOst = R"(image_width: 640
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [500.5, 0, 319.5, 0, 501.5, 239.5, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.01, -0.02, 0.0, 0.0, 0.0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [500, 0, 319.5, 0, 0, 501, 239.5, 0, 0, 0, 1, 0]
)";

const char* kPaperCamera = R"(<?xml version="1.0"?>
<opencv_storage>
<cameraMatrix type_id="opencv-matrix">
  <rows>3</rows>
  <cols>3</cols>
  <dt>d</dt>
  <data>
    600. 0. 320. 0. 600. 240. 0. 0. 1.</data></cameraMatrix>
</opencv_storage>
)";

const char* kPaperDist = R"(<?xml version="1.0"?>
<opencv_storage>
<distCoeffs type_id="opencv-matrix">
  <rows>5</rows>
  <cols>1</cols>
  <dt>d</dt>
  <data>
    -0.1 0.01 0. 0. 0.</data></distCoeffs>
</opencv_storage>
)";

Result<Calibration> read_text(const TempDir& dir, const std::string& name, const std::string& text) {
  write_file(dir.str(name), text);
  return read_calibration(dir.str(name));
}

TEST(CalibrationFile, ReadsOpenCvSamplesFormat) {
  TempDir dir;
  const Result<Calibration> c = read_text(dir, "cam.yml", kOpenCvSample);
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_DOUBLE_EQ(c->camera_matrix(0, 0), 560);
  EXPECT_DOUBLE_EQ(c->camera_matrix(1, 2), 236);
  ASSERT_EQ(c->distortion.size(), 5u);
  EXPECT_DOUBLE_EQ(c->distortion[3], -0.002);
  EXPECT_EQ(c->image_size, cv::Size(640, 480));
}

TEST(CalibrationFile, ReadsTheInteractiveCalibrationAppsFile) {
  TempDir dir;
  const Result<Calibration> c = read_text(dir, "cameraParameters.xml", kInteractive);
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_DOUBLE_EQ(c->camera_matrix(1, 1), 905);
  EXPECT_DOUBLE_EQ(c->distortion[4], 0.05);
  EXPECT_EQ(c->image_size, cv::Size(1280, 720));
}

TEST(CalibrationFile, ReadsRosOstYaml) {
  TempDir dir;
  const Result<Calibration> c = read_text(dir, "ost.yaml", kRosOst);
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_DOUBLE_EQ(c->camera_matrix(0, 0), 500.5);
  EXPECT_DOUBLE_EQ(c->camera_matrix(1, 2), 239.5);
  EXPECT_DOUBLE_EQ(c->distortion[1], -0.02);
  EXPECT_EQ(c->image_size, cv::Size(640, 480));
}

TEST(CalibrationFile, ReadsThePapersTwoFiles) {
  TempDir dir;
  write_file(dir.str("cameraMatrix.xml"), kPaperCamera);
  write_file(dir.str("distCoeffs.xml"), kPaperDist);
  const Result<Calibration> pair = read_calibration_pair(dir.str("cameraMatrix.xml"), dir.str("distCoeffs.xml"));
  ASSERT_TRUE(pair.ok()) << pair.error();
  EXPECT_DOUBLE_EQ(pair->camera_matrix(0, 2), 320);
  EXPECT_DOUBLE_EQ(pair->distortion[0], -0.1);
  // Named alone, cameraMatrix.xml is completed from the distCoeffs.xml beside it.
  const Result<Calibration> alone = read_calibration(dir.str("cameraMatrix.xml"));
  ASSERT_TRUE(alone.ok()) << alone.error();
  EXPECT_DOUBLE_EQ(alone->distortion[1], 0.01);
  std::filesystem::remove(dir.str("distCoeffs.xml"));
  const Result<Calibration> missing = read_calibration(dir.str("cameraMatrix.xml"));
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error(),
            dir.str("cameraMatrix.xml") + ": no distortion (looked for distortion_coefficients, dist_coeffs, distCoeffs)");
}

TEST(CalibrationFile, WrittenFilesReadBackInBothFormatsWithThePapersNames) {
  TempDir dir;
  Calibration c;
  c.camera_matrix = cv::Matx33d(561.25, 0, 321.5, 0, 556.75, 235.25, 0, 0, 1);
  c.distortion = {-0.2494, 0.081, 0.0001, -0.0002, 0};
  c.image_size = {640, 480};
  CalibrationFileExtras x;
  x.avg_reprojection_error = 0.1;
  x.per_view_reprojection_errors = {0.1, 0.09};
  x.std_intrinsics = {0.5, 0.5, 0.3, 0.3};
  x.std_distortion = {0.001, 0.002, 0.0001, 0.0001, 0};
  x.board = "chessboard 9x6";
  x.view_count = 2;
  for (const std::string name : {"cam.xml", "cam.yml"}) {
    ASSERT_TRUE(write_calibration(dir.str(name), c, x).ok());
    const Result<Calibration> back = read_calibration(dir.str(name));
    ASSERT_TRUE(back.ok()) << back.error();
    EXPECT_EQ(back->camera_matrix, c.camera_matrix) << name;
    EXPECT_EQ(back->distortion, c.distortion) << name;
    EXPECT_EQ(back->image_size, c.image_size) << name;
    const std::string text = test::read_file(dir.str(name));
    for (const char* key : {"cameraMatrix", "distCoeffs", "avg_reprojection_error", "per_view_reprojection_errors",
                            "std_dev_intrinsics_fx_fy_cx_cy", "std_dev_distortion", "view_count", "calibration_date"})
      EXPECT_NE(text.find(key), std::string::npos) << name << " lacks " << key;
  }
  ASSERT_TRUE(write_paper_files(dir.str(), c).ok());
  const Result<Calibration> paper = read_calibration_pair(dir.str("cameraMatrix.xml"), dir.str("distCoeffs.xml"));
  ASSERT_TRUE(paper.ok()) << paper.error();
  EXPECT_EQ(paper->camera_matrix, c.camera_matrix);
  EXPECT_EQ(paper->distortion, c.distortion);
}

TEST(CalibrationFile, AFailedWriteLeavesNothing) {
  TempDir dir;
  Calibration c;
  c.distortion = {0, 0, 0, 0, 0};
  write_file(dir.str("file"), "x");
  // A folder that does not exist, and a "folder" that is a file: one line each, nothing written.
  const Status a = write_calibration(dir.str("missing/cam.xml"), c, {});
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.error(), dir.str("missing/cam.xml") + ": cannot write (No such file or directory)");
  const Status b = write_calibration(dir.str("file/cam.yml"), c, {});
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error(), dir.str("file/cam.yml") + ": cannot write (Not a directory)");
  const Status e = write_calibration(dir.str("cam.txt"), c, {});
  EXPECT_EQ(e.error(), dir.str("cam.txt") + ": the file name must end in .xml, .yml or .yaml");
  const Status p = write_paper_files(dir.str("missing"), c);
  EXPECT_EQ(p.error(), dir.str("missing") + ": no such folder");
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) files += entry.path().filename() != "file";
  EXPECT_EQ(files, 0u);
}

// The calibration with the paper's files: when one of the three cannot be written, none is (no calibration file
// without the paper's files asked for, no new cameraMatrix.xml beside an old distCoeffs.xml).
TEST(CalibrationFile, TheFileAndThePapersFilesAreWrittenTogetherOrNotAtAll) {
  TempDir dir;
  Calibration c;
  c.camera_matrix = cv::Matx33d(560, 0, 322, 0, 555, 236, 0, 0, 1);
  c.distortion = {-0.25, 0.08, 0, 0, 0};
  c.image_size = {640, 480};
  std::filesystem::create_directory(dir.str("paper"));
  write_file(dir.str("paper/distCoeffs.xml"), "an older one");
  // distCoeffs.xml's temporary file cannot be made: a folder is in its place.
  std::filesystem::create_directory(dir.str("paper/distCoeffs.xml.arwb-saving"));
  const Status st = write_calibration(dir.str("cam.yml"), c, {}, dir.str("paper"));
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error(), dir.str("paper/distCoeffs.xml") + ": cannot write (Is a directory)");
  EXPECT_FALSE(std::filesystem::exists(dir.str("cam.yml")));
  EXPECT_FALSE(std::filesystem::exists(dir.str("paper/cameraMatrix.xml")));
  EXPECT_FALSE(std::filesystem::exists(dir.str("cam.yml.arwb-saving")));
  EXPECT_FALSE(std::filesystem::exists(dir.str("paper/cameraMatrix.xml.arwb-saving")));
  EXPECT_EQ(test::read_file(dir.str("paper/distCoeffs.xml")), "an older one");
  EXPECT_FALSE(write_paper_files(dir.str("paper"), c).ok());
  EXPECT_FALSE(std::filesystem::exists(dir.str("paper/cameraMatrix.xml")));
  // Once it can be written, all three are, and read back as one calibration.
  std::filesystem::remove(dir.str("paper/distCoeffs.xml.arwb-saving"));
  ASSERT_TRUE(write_calibration(dir.str("cam.yml"), c, {}, dir.str("paper")).ok());
  ASSERT_TRUE(read_calibration(dir.str("cam.yml")).ok());
  const Result<Calibration> paper = read_calibration(dir.str("paper/cameraMatrix.xml"));
  ASSERT_TRUE(paper.ok()) << paper.error();
  EXPECT_EQ(paper->camera_matrix, c.camera_matrix);
  EXPECT_EQ(paper->distortion, c.distortion);
  EXPECT_EQ(write_calibration(dir.str("cam2.yml"), c, {}, dir.str("nope")).error(), dir.str("nope") + ": no such folder");
  EXPECT_FALSE(std::filesystem::exists(dir.str("cam2.yml")));
}

struct Refusal {
  const char* name;
  std::string text;
  std::string message;   // after "<path>: ", or after "<path>" when it starts with ":LINE:"
};

class CalibrationFileRefuses : public testing::TestWithParam<Refusal> {};

TEST_P(CalibrationFileRefuses, WithOneLineNamingTheFileAndKey) {
  TempDir dir;
  const Refusal& r = GetParam();
  const std::string name = std::string(r.name) + (r.text.rfind("<", 0) == 0 ? ".xml" : ".yml");
  const Result<Calibration> c = read_text(dir, name, r.text);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error(), dir.str(name) + (r.message[0] == ':' ? "" : ": ") + r.message);
}

std::string sample_with(const std::string& from, const std::string& to) {
  std::string s = kOpenCvSample;
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CalibrationFileRefuses,
    testing::Values(
        Refusal{"no_camera", "%YAML:1.0\n---\nfoo: 1\n", "no camera matrix (looked for camera_matrix, cameraMatrix)"},
        Refusal{"two_by_three", sample_with("rows: 3\n   cols: 3\n   dt: d\n   data: [ 560., 0., 322., 0., 555., 236., 0., 0., 1. ]",
                                           "rows: 2\n   cols: 3\n   dt: d\n   data: [ 560., 0., 322., 0., 555., 236. ]"),
                "camera_matrix: expected 3x3 values, found 2x3"},
        Refusal{"not_finite", sample_with("-0.25, 0.08, 0.001", "-0.25, 0.08, .nan"),
                "distortion_coefficients: value 2 is not a finite number"},
        Refusal{"negative_focal", sample_with("0., 555., 236.", "0., -555., 236."),
                "camera_matrix: focal length fy -555 is not 1 to 1e+07 pixels"},
        Refusal{"text_value", sample_with("560., 0., 322.", "abc, 0., 322."),
                "camera_matrix: value 0 is not a number"},
        Refusal{"count_mismatch", sample_with("cols: 5\n   dt: d\n   data: [ -0.25, 0.08, 0.001, -0.002, 0. ]",
                                             "cols: 5\n   dt: d\n   data: [ -0.25, 0.08, 0.001 ]"),
                "distortion_coefficients: 1x5 declared, 3 values given"},
        Refusal{"three_coefficients", sample_with("rows: 1\n   cols: 5\n   dt: d\n   data: [ -0.25, 0.08, 0.001, -0.002, 0. ]",
                                                 "rows: 1\n   cols: 3\n   dt: d\n   data: [ -0.25, 0.08, 0.001 ]"),
                "distortion_coefficients: 3 values; expected 4, 5, 8, 12 or 14 (k1 k2 p1 p2 [k3 ...])"},
        Refusal{"not_a_camera", sample_with("0., 0., 1. ]", "0., 0., 2. ]"),
                "camera_matrix: not a camera matrix (its last row must be 0 0 1 and the value under fx 0)"},
        Refusal{"fisheye", std::string(kRosOst).replace(std::string(kRosOst).find("plumb_bob"), 9, "equidistant"),
                "distortion_model: equidistant is not read (plumb_bob and rational_polynomial are)"},
        Refusal{"bad_size", sample_with("image_width: 640", "image_width: -640"),
                "image size -640x480 is not 1..65536"},
        Refusal{"deep_xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n" + std::string(40, ' ') + [] {
                  std::string s;
                  for (int i = 0; i < 40; ++i) s += "<a>";
                  return s;
                }(), ":3: nested deeper than 32 levels"},
        Refusal{"doctype", "<?xml version=\"1.0\"?>\n<!DOCTYPE x [<!ENTITY a \"b\">]>\n<opencv_storage/>\n",
                ":2: DOCTYPE and CDATA are not read in a calibration file"},
        Refusal{"deep_yaml", "%YAML:1.0\n---\ncamera_matrix: " + std::string(40, '[') + "\n",
                ":3: nested deeper than 32 levels"},
        Refusal{"empty", "\n\n", "empty file"}),
    [](const testing::TestParamInfo<Refusal>& p) { return std::string(p.param.name); });

// OpenCV's XML parser recurses once per element: 40,000 nested elements overflow its stack (a crash before our
// check; fuzz/regressions/calibration/nested_40000_deep.xml).
TEST(CalibrationFile, RefusesXmlNestedDeeperThanItsParserCanTake) {
  TempDir dir;
  std::string text = "<?xml version=\"1.0\"?>\n<opencv_storage>\n";
  for (int i = 0; i < 40000; ++i) text += "<a>";
  const Result<Calibration> c = read_text(dir, "deep.xml", text);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error(), dir.str("deep.xml") + ":3: nested deeper than 32 levels");
}

TEST(CalibrationFile, RefusesWhatIsNotARegularFile) {
  TempDir dir;
  std::filesystem::create_directory(dir.str("folder.yml"));
  const Result<Calibration> c = read_calibration(dir.str("folder.yml"));
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error(), dir.str("folder.yml") + ": not a regular file (a folder)");
  const Result<Calibration> none = read_calibration(dir.str("none.yml"));
  EXPECT_EQ(none.error(), dir.str("none.yml") + ": no such file");
}

TEST(CalibrationFile, ScalesToASourceOfTheSameAspectRatioAndRefusesAnother) {
  TempDir dir;
  const Result<Calibration> c = read_text(dir, "hd.xml", kInteractive);   // 1280x720
  ASSERT_TRUE(c.ok()) << c.error();
  const Result<Calibration> half = calibration_for_size(*c, {640, 360});
  ASSERT_TRUE(half.ok()) << half.error();
  EXPECT_DOUBLE_EQ(half->camera_matrix(0, 0), 450);
  EXPECT_DOUBLE_EQ(half->camera_matrix(1, 1), 452.5);
  EXPECT_DOUBLE_EQ(half->camera_matrix(0, 2), (640 + 0.5) / 2 - 0.5);
  EXPECT_DOUBLE_EQ(half->camera_matrix(1, 2), (360 + 0.5) / 2 - 0.5);
  EXPECT_EQ(half->distortion, c->distortion);   // distortion works on normalised coordinates: unchanged
  EXPECT_EQ(half->image_size, cv::Size(640, 360));
  const Result<Calibration> same = calibration_for_size(*c, {1280, 720});
  EXPECT_EQ(same->camera_matrix, c->camera_matrix);
  const Result<Calibration> other = calibration_for_size(*c, {640, 480});
  ASSERT_FALSE(other.ok());
  EXPECT_EQ(other.error(),
            dir.str("hd.xml") + ": made for 1280x720 (16:9), the source is 640x480 (4:3); calibrate at this size");
}

// The rule holds at the source's size even when the size is the file's own: the paper's pair reads its distortion
// from distCoeffs.xml after the camera file's size, so the reader alone never sees the two together.
TEST(CalibrationFile, TheCameraRuleHoldsAtTheFilesOwnSizeToo) {
  Calibration c;
  c.camera_matrix = cv::Matx33d(560, 0, 322, 0, 555, 236, 0, 0, 1);
  c.distortion = {-0.25, 0.08, 0, 0, 0, 1e6, 0, 0};
  c.image_size = {640, 480};
  c.source = "cameraMatrix.xml + distCoeffs.xml";
  const Result<Calibration> r = calibration_for_size(c, {640, 480});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().rfind("cameraMatrix.xml + distCoeffs.xml: its distortion cannot be undone at pixel (0, 0) of a "
                            "640x480 picture", 0), 0u) << r.error();
  c.distortion = {-0.25, 0.08, 0, 0, 0};
  EXPECT_TRUE(calibration_for_size(c, {640, 480}).ok());
}

}  // namespace
}  // namespace arwb
