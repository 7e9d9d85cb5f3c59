// The QR code `arwb serve` prints: read back from its terminal text by ZBar (Debian: libzbar-dev), a decoder that
// shares nothing with libqrencode or our half-block printing. (Debian's OpenCV has no QR decoder: no quirc.)
#include "serve/qr_code.hpp"

#include "support/qr_reader.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <string>
#include <vector>

namespace arwb::serve {
namespace {

// The terminal text back to modules: each character is two modules, one above the other, dark as ink. Escape
// sequences (the ansi form's colours) are skipped.
cv::Mat modules_of(const std::string& text) {
  std::vector<std::vector<int>> rows;
  std::vector<int> top, bottom;
  for (std::size_t i = 0; i < text.size();) {
    if (text[i] == '\x1b') {
      i = text.find('m', i) + 1;
      continue;
    }
    if (text[i] == '\n') {
      rows.push_back(top);
      rows.push_back(bottom);
      top.clear();
      bottom.clear();
      ++i;
      continue;
    }
    int t = 0, b = 0;
    if (text.compare(i, 3, "\u2588") == 0) t = b = 1, i += 3;
    else if (text.compare(i, 3, "\u2580") == 0) t = 1, i += 3;
    else if (text.compare(i, 3, "\u2584") == 0) b = 1, i += 3;
    else if (text[i] == ' ') ++i;
    else ADD_FAILURE() << "unexpected byte " << int(static_cast<unsigned char>(text[i])) << " at " << i, ++i;
    top.push_back(t);
    bottom.push_back(b);
  }
  cv::Mat m(int(rows.size()), int(rows.empty() ? 0 : rows[0].size()), CV_8U, cv::Scalar(255));
  for (int y = 0; y < m.rows; ++y) {
    EXPECT_EQ(rows[y].size(), std::size_t(m.cols)) << "row " << y;
    for (int x = 0; x < m.cols && x < int(rows[y].size()); ++x) m.at<uchar>(y, x) = rows[y][x] ? 0 : 255;
  }
  return m;
}

std::string decoded(const std::string& text) {
  const cv::Mat modules = modules_of(text);
  cv::Mat big;
  cv::resize(modules, big, {}, 8, 8, cv::INTER_NEAREST);
  return test::read_qr(big);
}

TEST(QrCode, TheTerminalTextReadsBackAsTheAddress) {
  for (const std::string url : {"http://127.0.0.1:8000/", "http://127.0.0.1:54321/",
                                "https://example.org/a/rather/longer/path/to/the/museum/bundle/index.html"}) {
    Result<QrCode> code = make_qr(url);
    ASSERT_TRUE(code.ok()) << code.error();
    EXPECT_EQ(code->dark.size(), std::size_t(code->size) * code->size);
    EXPECT_EQ(decoded(qr_terminal_text(*code, false)), url);
    const std::string ansi = qr_terminal_text(*code, true);
    EXPECT_NE(ansi.find("\x1b[30;107m"), std::string::npos);
    EXPECT_EQ(decoded(ansi), url);
    // A quiet zone of 4 modules on every side: the text is the code's size plus 8, two module rows a line.
    EXPECT_EQ(modules_of(qr_terminal_text(*code, false)).cols, code->size + 8);
  }
}

TEST(QrCode, TextsNoCodeHoldsAreRefusedSayingSo) {
  EXPECT_EQ(make_qr("").error(), "a QR code needs a text");
  EXPECT_EQ(make_qr(std::string(5000, 'x')).error(), "no QR code holds 5000 characters");
}

}  // namespace
}  // namespace arwb::serve
