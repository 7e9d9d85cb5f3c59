// open_source (synthetic_source.hpp), apart from the synthetic source: a program that makes synthetic frames and
// opens no other source (a test of calibration, of pose) then links none of OpenCV's video readers.
#include "synth/synthetic_source.hpp"

namespace arwb {

std::unique_ptr<FrameSource> open_source(const SourceSpec& spec, std::string* error) {
  if (spec.kind != SourceKind::synthetic) return open_capture_source(spec, error);
  if (error) error->clear();
  return std::make_unique<SyntheticSource>();
}

}  // namespace arwb
