#include "cli/commands.hpp"

namespace arwb {

std::span<const Subcommand> arwb_subcommands() {
  static constexpr Subcommand kSubcommands[] = {
      {"detect", cmd_detect, "detect markers in images, folders or videos (--json: one line per frame)"},
      {"markers", cmd_markers, "write marker PNGs, or a printable PDF/SVG sheet at true size"},
      {"synth", cmd_synth, "make synthetic photographs of markers with a truth.jsonl"},
      {"calibrate", cmd_calibrate, "calibrate a camera from a video or folder of chessboard images, with a report"},
      {"bench", cmd_bench, "compare arwb with OpenCV aruco and AprilTag on a synthetic set"},
      {"make-media", cmd_make_media, "paint the example scenes' pictures and clip (no downloads)"},
      {"lab", cmd_lab, "the paper's recognition experiment: size x distance x light, every detector on the same frames"},
      {"export", cmd_export, "a scene, its media, calibration and marker sheet as a checked bundle for arwb play"},
      {"serve", cmd_serve, "serve a bundle's phone page (export --web) on 127.0.0.1, with a QR code of its address"},
      {"render", cmd_render, "composite a scene's media onto a video, images or the synthetic source (no display)"},
  };
  return kSubcommands;
}

}  // namespace arwb
