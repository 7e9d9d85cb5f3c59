// The lab on real videos: a folder of clips, each of one marker shown to the camera, listed in videos.csv with
// the conditions it was filmed in. P_Rec is computed exactly as the paper does (frames in which the detector
// reported the marker / frames in which the marker is visible x 100): the visible frames are the whole clip, or
// the span its row gives. The same table, CSV and JSON as a rendered run.
//
// videos.csv, one header line then one row per clip (blank lines and lines starting with # are skipped):
//   file,id,dictionary,size_mm,distance_m,lux[,first_frame,last_frame]
//   clips/m17_65mm_1m_850lx.mp4,17,ARUCO_ORIGINAL,65,1,850
//   clips/m17_65mm_2m_850lx.mp4,17,ARUCO_ORIGINAL,65,2,850,12,140
// Files are relative to the folder and must stay inside it; first_frame and last_frame count from 0, inclusive.
#pragma once

#include "lab/run.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace arwb::lab {

struct VideoRow {
  std::string file;            // as written
  std::string path;            // resolved inside the folder
  int id = -1;
  std::string dictionary;
  double size_mm = 0, distance_m = 0, lux = 0;
  int64_t first_frame = 0, last_frame = -1;   // -1: to the end
  int line = 0;
};

// Reads DIR/videos.csv. One line per problem's first: "videos.csv:3: size_mm 'abc' is not a number",
// "videos.csv:4: clips/x.mp4: no such file", "videos.csv:5: id 1024 is not a marker of ARUCO_ORIGINAL (0 to 1023)",
// "videos.csv:1: the header must be file,id,dictionary,size_mm,distance_m,lux[,first_frame,last_frame]".
Result<std::vector<VideoRow>> read_video_list(const std::string& dir);

// A row's fields as save_video_row takes them: the dictionary known, the id one of its markers, size_mm, distance_m
// and lux in range, the span (when given) in order. The one line of the first problem, naming the field.
Status check_video_row(const VideoRow& row);

// Marks a clip in DIR/videos.csv, as the Lab workspace does from the clip playing in the live view: `clip` is the
// video's path (it must be inside DIR; the row names it relative to DIR), the other fields as VideoRow's
// (first_frame and last_frame both given, or last_frame -1 for the whole clip). A row for the same file is replaced,
// others are kept as they were (comments too); the file is created with its header when missing, and written whole
// or not at all. Every problem is one line naming the field: "last_frame 3 is before first_frame 8".
Status save_video_row(const std::string& dir, const std::string& clip, const VideoRow& row);

// Every clip through every detector. Cells are the distinct (size, distance, light) of the rows, in the paper's
// order (larger first). A clip that cannot be read, or ends before its span, is reported in *warnings and
// counted for the frames it has.
Result<LabResults> run_videos(const std::string& dir, const std::vector<VideoRow>& rows, const LabOptions& options,
                              std::vector<std::string>* warnings, const std::function<void(int, int)>& progress = {});

}  // namespace arwb::lab
