// The parameter table: defaults, ranges and YAML presets.
#include "detect/detector.hpp"
#include "detect/params.hpp"
#include "detect/pipeline.hpp"
#include "detect/kernels/simd.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <bit>
#include <cmath>

using namespace arwb;

TEST(Params, TableDrivesDefaultsRangesAndYaml) {
  const DetectorParams p;
  for (const auto& info : param_table()) {
    EXPECT_EQ(get_param(p, info), info.default_value) << info.name;
    EXPECT_LE(info.min_value, info.default_value) << info.name;
    EXPECT_GE(info.max_value, info.default_value) << info.name;
    EXPECT_STRNE(info.help, "") << info.name;
    EXPECT_TRUE(param_stage_known(info.stage)) << info.name << " names stage " << info.stage;
  }
  DetectorParams q;
  std::string err;
  EXPECT_FALSE(set_param(q, *find_param("threshold_window_px"), 2.5, &err));
  EXPECT_NE(err.find("threshold_window_px"), std::string::npos);
  EXPECT_FALSE(set_param(q, *find_param("warp_cell_px"), 1000, &err));
  EXPECT_NE(err.find("1..32"), std::string::npos);

  test::TempDir dir;
  q.threshold_offset = 11;
  q.warp_cell_px = 6;
  ASSERT_TRUE(save_params_yaml(dir.str("p.yml"), q, &err)) << err;
  DetectorParams back;
  std::vector<std::string> errors;
  ASSERT_TRUE(load_params_yaml(dir.str("p.yml"), back, &errors));
  EXPECT_EQ(back.threshold_offset, 11);
  EXPECT_EQ(back.warp_cell_px, 6);

  test::write_file(dir.str("plain.yml"), "threshold_offset: 9\n");  // no %YAML header, as people write it
  ASSERT_TRUE(load_params_yaml(dir.str("plain.yml"), back, &errors));
  EXPECT_EQ(back.threshold_offset, 9);
}

TEST(Params, BadPresetsChangeNothingAndNameFileAndKey) {
  test::TempDir dir;
  DetectorParams p;
  std::vector<std::string> errors;
  test::write_file(dir.str("bad.yml"), "threshold_offset: 3\nno_such_param: 1\nwarp_cell_px: 99\n");
  EXPECT_FALSE(load_params_yaml(dir.str("bad.yml"), p, &errors));
  EXPECT_EQ(p.threshold_offset, DetectorParams{}.threshold_offset);  // nothing applied
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_NE(errors[0].find("bad.yml"), std::string::npos);
  EXPECT_NE(errors[0].find("no_such_param"), std::string::npos);
  EXPECT_NE(errors[1].find("warp_cell_px"), std::string::npos);
  errors.clear();
  test::write_file(dir.str("broken.yml"), "threshold_offset: [1, 2\n  : :\n");
  EXPECT_FALSE(load_params_yaml(dir.str("broken.yml"), p, &errors));
  ASSERT_FALSE(errors.empty());
  EXPECT_NE(errors[0].find("broken.yml"), std::string::npos);
}

// Presets from before the resize became acquisition's still load; their resize keys are named in a note, never
// silently applied or dropped.

TEST(Params, OldPresetsWithResizeKeysLoadWithANote) {
  test::TempDir dir;
  test::write_file(dir.str("old.yml"), "resize_width: 0\nresize_height: 0\nthreshold_offset: 9\n");
  DetectorParams p;
  std::vector<std::string> errors, notes;
  ASSERT_TRUE(load_params_yaml(dir.str("old.yml"), p, &errors, &notes));
  EXPECT_TRUE(errors.empty());
  EXPECT_EQ(p.threshold_offset, 9);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("old.yml: resize_width"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("--resize"), std::string::npos) << notes[0];

  test::write_file(dir.str("small.yml"), "resize_width: 320\nwarp_cell_px: 6\n");
  notes.clear();
  ASSERT_TRUE(load_params_yaml(dir.str("small.yml"), p, &errors, &notes));
  EXPECT_EQ(p.warp_cell_px, 6);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("resize_width = 320 is not applied"), std::string::npos) << notes[0];

  // The shipped presets load without a note: they no longer name a resize.
  for (const char* name : {"default.yml", "small-markers.yml", "fast.yml"}) {
    notes.clear();
    errors.clear();
    EXPECT_TRUE(load_params_yaml(std::string(ARWB_SOURCE_DIR) + "/assets/presets/" + name, p, &errors, &notes))
        << name;
    EXPECT_TRUE(notes.empty()) << name;
  }
  // default.yml undoes any tuning: every parameter of the table, at its default.
  DetectorParams tuned;
  for (const ParamInfo& info : param_table()) {
    const double other = info.default_value == info.max_value ? info.min_value : info.max_value;
    ASSERT_TRUE(set_param(tuned, info, other)) << info.name;
  }
  ASSERT_TRUE(load_params_yaml(std::string(ARWB_SOURCE_DIR) + "/assets/presets/default.yml", tuned, &errors));
  for (const ParamInfo& info : param_table())
    EXPECT_EQ(get_param(tuned, info), info.default_value) << info.name << " is not in default.yml";
  EXPECT_EQ(tuned, DetectorParams{});
  // Still an unknown key elsewhere is an error, and nothing changes.
  test::write_file(dir.str("typo.yml"), "resize_width: 0\nthreshold_ofset: 3\n");
  const DetectorParams before = p;
  EXPECT_FALSE(load_params_yaml(dir.str("typo.yml"), p, &errors, &notes));
  EXPECT_EQ(p, before);
}

// decimation: the search image is the block mean, a factor that would leave fewer than 64 pixels a side is lowered,
// and contours found on it come back in the grey image's pixels, their length in those pixels.
