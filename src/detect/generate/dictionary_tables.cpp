// Writes the predefined dictionaries' codes, as OpenCV's aruco module has them, to the file named by its argument:
// a C++ table the detector compiles in (dictionary.cpp), so that the detector itself needs no aruco module. Run by
// the build (src/detect/CMakeLists.txt); not part of any library.
#include <opencv2/aruco.hpp>

#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace {

// A marker's bits row-major, the top-left the most significant, 1 white: Dictionary::pack's order.
uint64_t pack(const cv::Mat& bits) {
  uint64_t code = 0;
  for (int r = 0; r < bits.rows; ++r)
    for (int c = 0; c < bits.cols; ++c) code = (code << 1) | (bits.at<uint8_t>(r, c) ? 1u : 0u);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: dictionary_tables OUT.inc\n");
    return 2;
  }
  using namespace cv::aruco;
  const std::vector<std::pair<const char*, PREDEFINED_DICTIONARY_NAME>> names = {
      {"4X4_50", DICT_4X4_50},     {"4X4_100", DICT_4X4_100},     {"4X4_250", DICT_4X4_250},
      {"4X4_1000", DICT_4X4_1000}, {"5X5_50", DICT_5X5_50},       {"5X5_100", DICT_5X5_100},
      {"5X5_250", DICT_5X5_250},   {"5X5_1000", DICT_5X5_1000},   {"6X6_50", DICT_6X6_50},
      {"6X6_100", DICT_6X6_100},   {"6X6_250", DICT_6X6_250},     {"6X6_1000", DICT_6X6_1000},
      {"7X7_50", DICT_7X7_50},     {"7X7_100", DICT_7X7_100},     {"7X7_250", DICT_7X7_250},
      {"7X7_1000", DICT_7X7_1000}, {"APRILTAG_16h5", DICT_APRILTAG_16h5}, {"APRILTAG_25h9", DICT_APRILTAG_25h9},
      {"APRILTAG_36h10", DICT_APRILTAG_36h10}, {"APRILTAG_36h11", DICT_APRILTAG_36h11},
  };
  std::string out =
      "// Generated at build time by src/detect/generate/dictionary_tables.cpp from OpenCV's aruco module.\n";
  std::string table;
  for (size_t k = 0; k < names.size(); ++k) {
    const cv::Ptr<Dictionary> d = getPredefinedDictionary(names[k].second);
    out += "inline constexpr uint64_t kCodes" + std::to_string(k) + "[] = {";
    for (int id = 0; id < d->bytesList.rows; ++id) {
      char hex[32];
      std::snprintf(hex, sizeof hex, "%s0x%llxull", id == 0 ? "\n    " : id % 6 ? ", " : ",\n    ",
                    static_cast<unsigned long long>(pack(Dictionary::getBitsFromByteList(d->bytesList.row(id),
                                                                                       d->markerSize))));
      out += hex;
    }
    out += "};\n";
    table += "    {\"" + std::string(names[k].first) + "\", " + std::to_string(d->markerSize) + ", " +
             std::to_string(d->maxCorrectionBits) + ", " + std::to_string(d->bytesList.rows) + ", kCodes" +
             std::to_string(k) + "},\n";
  }
  out += "inline constexpr PredefinedCodes kPredefined[] = {\n" + table + "};\n";
  FILE* f = std::fopen(argv[1], "wb");
  if (!f || std::fwrite(out.data(), 1, out.size(), f) != out.size() || std::fclose(f) != 0) {
    std::fprintf(stderr, "dictionary_tables: cannot write %s\n", argv[1]);
    return 1;
  }
  return 0;
}
