// `arwb bench --video`: detection over synthetic video sequences, arwb searching every frame whole against arwb in
// video mode (detect/video_search.hpp) and the peers, one thread, the same frames. Each sequence is the synthetic
// world (synth/synthetic_world.hpp: markers moving, turning, coming and going under changing light) at 20 frames
// a second, and one more marker lying still in a corner, away from the group, shown from a frame past the start
// on: the frames until each detector reports it are how soon a marker coming into view is found.
#pragma once

#include "detect/dictionary.hpp"
#include "detect/params.hpp"

#include <string>
#include <vector>

namespace arwb {

struct VideoBenchOptions {
  int sequences = 2;           // per resolution and dictionary; the second and later further away (smaller markers)
  int frames = 60;             // per sequence
  unsigned seed = 1;
  int reps = 1;                // runs per frame, the fastest kept (video mode reruns from the same state)
  std::vector<Dictionary> dicts;
  std::vector<std::string> peers;   // any of opencv, aruco3, apriltag
  DetectorParams params{};
  bool json = false;
};

// Prints the table (or one JSON object) and returns the exit status.
int bench_video(const VideoBenchOptions& o);

}  // namespace arwb
