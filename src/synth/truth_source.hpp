// A frame source that knows exactly which markers its last frame shows (the synthetic source, a lab cell): the
// workbench puts them in the frame as its truth, for the overlays, the peers' comparison and "Why not detected?".
#pragma once

#include "capture/source.hpp"
#include "synth/synth.hpp"

#include <vector>

namespace arwb {

class TruthSource : public FrameSource {
 public:
  // The exact markers of the frame `next` last returned, in its pixels.
  virtual const std::vector<TruthMarker>& truth() const = 0;
};

}  // namespace arwb
